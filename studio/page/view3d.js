// rcb4 ui: the robot drawn in 3D (three.js from Debian's libjs-three, served by rcb4 ui) from the
// profile's body (the hello's "body": links of boxes, cylinders and spheres; joints with origin and
// axis, as URDF). Two copies: the measured pose, solid, and the edited or target pose, a ghost.
// Orbit, zoom and pan with the mouse (OrbitControls); a click on a limb selects its joint; a joint
// beyond its limit is drawn red.

const deg = Math.PI / 180;

/**
 * Draws the robot of @p hello into @p box. Resolves to the view, or to null (with a message in the
 * box) when three.js or the body is missing. opts.onSelect(jointName) is called on a click,
 * opts.onHand(jointName, degrees) on a Shift+drag of the selected joint.
 */
export async function createView(box, hello, opts = {}) {
  const note = (text) => { box.replaceChildren(); box.append(Object.assign(document.createElement('p'), { className: 'muted small', textContent: text })); return null; };
  if (!hello.body) return note('no 3D view: this robot profile has no kinematics: section (docs/robot-profiles.md)');
  let THREE, OrbitControls;
  try {
    THREE = await import('/vendor/three/build/three.module.js');
    ({ OrbitControls } = await import('/vendor/three/examples/jsm/controls/OrbitControls.js'));
  } catch {
    return note('no 3D view: rcb4 ui found no three.js (apt install libjs-three, or rcb4 ui --three DIR)');
  }
  const canvas = document.createElement('canvas');
  canvas.id = 'view3d-canvas';
  canvas.setAttribute('aria-label', 'the robot in 3D: drag to turn, wheel to zoom, click a limb to select its joint');
  canvas.tabIndex = 0;
  box.replaceChildren(canvas);
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  } catch {
    return note('no 3D view: this browser has no WebGL');
  }
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f6fa);
  const camera = new THREE.PerspectiveCamera(35, 1, 5, 20000);
  camera.up.set(0, 0, 1);  // z up, as the profile and URDF
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8890a0, 0.9));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.set(600, -400, 900);
  scene.add(sun);

  const joints = new Map(hello.joints.map((j) => [j.name, j]));
  const solid = build(THREE, hello.body, { color: 0xc9ced8, opacity: 1 });
  const ghost = build(THREE, hello.body, { color: 0x2f6fdf, opacity: 0.22 });
  scene.add(solid.root, ghost.root);
  ghost.root.visible = false;

  // The floor under the feet at the zero pose, and the camera on the robot.
  const bounds = new THREE.Box3().setFromObject(solid.root);
  const grid = new THREE.GridHelper(800, 16, 0xb8c0cc, 0xdde1e8);
  grid.rotation.x = Math.PI / 2;
  grid.position.z = bounds.min.z;
  scene.add(grid);
  const centre = bounds.getCenter(new THREE.Vector3());
  const size = bounds.getSize(new THREE.Vector3()).length();
  camera.position.set(centre.x + size * 1.1, centre.y - size * 1.3, centre.z + size * 0.35);
  const controls = new OrbitControls(camera, canvas);
  controls.target.copy(centre);
  controls.update();

  let selected = null;
  const measured = {}, edited = {};
  const paint = (copy, angles) => {
    for (const [name, m] of copy.meshes) {
      const j = joints.get(m.joint);
      const a = angles[m.joint];
      const beyond = j && a !== undefined && a !== null && (a < j.lower - 0.05 || a > j.upper + 0.05);
      m.material.color.setHex(copy.unknown ? 0x9a9a9a : beyond ? 0xd0342c : copy.color);
      m.material.transparent = !!copy.unknown || copy.opacity < 1;
      m.material.opacity = copy.unknown ? 0.35 : copy.opacity;
      m.material.emissive?.setHex(m.joint && m.joint === selected ? 0x1b3f8a : 0x000000);
      void name;
    }
  };
  const pose = (copy, angles) => {
    for (const [name, p] of copy.pivots) {
      const a = angles[name];
      p.pivot.quaternion.setFromAxisAngle(p.axis, Number.isFinite(a) ? a * deg : 0);
    }
    paint(copy, angles);
  };

  // A click (not a drag) on a limb selects the joint that turns it. Shift+drag turns the selected
  // joint by hand (opts.onHand: the virtual board's hand, for a freed joint), up and down.
  const ray = new THREE.Raycaster();
  let down = null, turning = null;
  canvas.addEventListener('pointerdown', (e) => {
    down = [e.clientX, e.clientY];
    if (e.shiftKey && selected && opts.onHand) {
      turning = { y: e.clientY, from: measured[selected] ?? 0, sent: 0 };
      controls.enabled = false;
      canvas.setPointerCapture(e.pointerId);
    }
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!turning) return;
    const now = performance.now();
    if (now - turning.sent < 50) return;  // at most 20 turns a second
    turning.sent = now;
    opts.onHand(selected, turning.from + (turning.y - e.clientY) * 0.5);  // half a degree a pixel
  });
  const endTurn = () => { turning = null; controls.enabled = true; };
  canvas.addEventListener('pointercancel', endTurn);
  canvas.addEventListener('pointerup', (e) => {
    if (turning) { endTurn(); return; }
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
    const r = canvas.getBoundingClientRect();
    ray.setFromCamera(new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1), camera);
    const hit = ray.intersectObjects([...solid.meshes.values()], false)[0];
    const joint = hit?.object.userData.joint;
    if (joint) { view.select(joint); opts.onSelect?.(joint); }
  });

  const stats = { frames: 0, started: performance.now() };
  let shown = [0, 0];
  const resize = () => {
    // As wide as its column, and short enough that the pose being edited fits below it in the
    // window (the view stays at the top while the editor scrolls: style.css).
    const w = box.clientWidth || 400;
    const h = Math.max(200, Math.min(520, Math.round(w * 0.7), Math.round(window.innerHeight * 0.42)));
    if (w === shown[0] && h === shown[1]) return;  // a resize that changes nothing redraws nothing
    shown = [w, h];
    renderer.setSize(w, h, false);
    canvas.style.width = `${w}px`;
    canvas.style.height = `${h}px`;
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  };
  // Drawn when something changed (the state, the ghost, the camera, the size), not 60 times a
  // second while nothing moves: an idle page costs no CPU (software GL draws slowly).
  let pending = false;
  const frame = () => {
    pending = false;
    renderer.render(scene, camera);
    stats.frames += 1;
  };
  const invalidate = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(frame);
  };
  new ResizeObserver(() => { resize(); invalidate(); }).observe(box);
  window.addEventListener('resize', () => { resize(); invalidate(); });  // a taller or shorter window
  resize();
  controls.addEventListener('change', invalidate);
  invalidate();

  const view = {
    stats,
    canvas,
    /** The measured angles (joint → degrees; null: unknown). */
    setMeasured(angles) {
      if (Object.entries(angles).every(([k, a]) => measured[k] === a)) return;  // nothing moved: nothing to draw
      Object.assign(measured, angles);
      invalidate();
      // Unknown angles (the board does not answer) are drawn as nothing, never as 0°: a joint
      // without one keeps its last pose, and the body is greyed out while any is unknown.
      const known = Object.fromEntries(Object.entries(measured).filter(([, a]) => Number.isFinite(a)));
      solid.unknown = Object.keys(known).length < Object.keys(measured).length;
      pose(solid, { ...solid.last, ...known });
      solid.last = { ...solid.last, ...known };
      stats.unknown = solid.unknown;
    },
    /** The ghost's angles (joint → degrees), or null to hide it. */
    setGhost(angles) {
      invalidate();
      ghost.root.visible = !!angles;
      if (angles) { for (const k of Object.keys(edited)) delete edited[k]; Object.assign(edited, angles); pose(ghost, edited); }
    },
    /** Highlights joint @p name's limb (null: none). */
    select(name) { selected = name; paint(solid, measured); paint(ghost, edited); invalidate(); },
    get selected() { return selected; },
    /** The ghost's angles as last set (null while hidden): tests and the benchmark read it. */
    get ghost() { return ghost.root.visible ? { ...edited } : null; },
  };
  return view;
}

/** The robot as a tree of groups: a link's shapes in its group, each joint a frame and a pivot. */
function build(THREE, body, look) {
  const links = new Map(), pivots = new Map(), meshes = new Map();
  const turnedBy = new Map(body.joints.map((j) => [j.child, j]));
  for (const l of body.links) {
    const g = new THREE.Group();
    g.name = l.name;
    const joint = turnedBy.get(l.name);
    l.shapes.forEach((s, k) => {
      let geo;
      if (s.type === 'box') geo = new THREE.BoxBufferGeometry(s.size[0], s.size[1], s.size[2]);
      else if (s.type === 'cylinder') geo = new THREE.CylinderBufferGeometry(s.size[0], s.size[0], s.size[1], 20).rotateX(Math.PI / 2);
      else geo = new THREE.SphereBufferGeometry(s.size[0], 16, 12);
      const mat = new THREE.MeshLambertMaterial({ color: look.color, transparent: look.opacity < 1, opacity: look.opacity, depthWrite: look.opacity >= 1 });
      const mesh = new THREE.Mesh(geo, mat);
      mesh.position.set(...s.xyz);
      mesh.rotation.set(s.rpy[0] * deg, s.rpy[1] * deg, s.rpy[2] * deg, 'ZYX');  // URDF's rpy: fixed axes x, y, z
      mesh.userData.joint = joint && !joint.fixed ? joint.name : null;
      g.add(mesh);
      meshes.set(`${l.name}:${k}`, mesh);
    });
    links.set(l.name, g);
  }
  for (const j of body.joints) {
    const frame = new THREE.Group();
    frame.position.set(...j.xyz);
    frame.rotation.set(j.rpy[0] * deg, j.rpy[1] * deg, j.rpy[2] * deg, 'ZYX');
    const pivot = new THREE.Group();
    frame.add(pivot);
    pivot.add(links.get(j.child));
    links.get(j.parent).add(frame);
    if (!j.fixed) pivots.set(j.name, { pivot, axis: new THREE.Vector3(...j.axis).normalize() });
  }
  return { root: links.get(body.root), pivots, meshes, color: look.color, opacity: look.opacity };
}
