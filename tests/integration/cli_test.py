#!/usr/bin/env python3
# The rcb4 command-line tool used as a newcomer would: every subcommand, its --help, its errors
# and exit codes, against the in-process virtual board and against an independent RCB-4 stand-in
# written here in Python from protocol.md (no project code), on a pseudo-terminal. Expected frames
# are written by hand from protocol.md.
# SPDX-License-Identifier: BSL-1.0
import json
import os
import signal
import subprocess
import sys
import threading
import time
import tty

RCB4 = sys.argv[1]
from checks import check, finish
from standin import StandIn


def run(*args, stdin=None, timeout=60):
    p = subprocess.run([RCB4, *args], input=stdin, capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def expect_ok(args, contains, what=None, stdin=None):
    rc, out, err = run(*args, stdin=stdin)
    check(rc == 0 and contains in out, (what or " ".join(args)) + (f"  (rc {rc}, out {out[:200]!r}, err {err[:200]!r})" if rc or contains not in out else ""))
    return out


def expect_rc(args, rc_wanted, err_contains, what=None):
    rc, out, err = run(*args)
    check(rc == rc_wanted and err_contains in err, (what or " ".join(args)) + f" -> exit {rc_wanted}" + (f"  (got {rc}: {err[:200]!r})" if rc != rc_wanted or err_contains not in err else ""))


# ---- help and usage --------------------------------------------------------------------------
expect_ok(["--help"], "exit codes")
expect_rc([], 2, "", "no arguments")
expect_rc(["frobnicate"], 2, "unknown command")
for sub in ["ping", "version", "config", "read", "write", "servo", "sensors", "monitor", "motion", "bench",
            "list", "doctor", "decode", "encode", "serve"]:
    rc, out, err = run(sub, "--help")
    check(rc == 0 and f"Usage: rcb4 {sub}" in out, f"{sub} --help is the command's own help")

# ---- against the in-process virtual board (no --device) --------------------------------------
expect_ok(["ping"], "ACK from the in-process virtual board")
expect_ok(["ping", "--count", "20"], "20 pings")
expect_ok(["version"], "CB-4 V1.0      090715")
cfg = json.loads(expect_ok(["--json", "config"], "{"))
check(cfg["word"] == 0x008B and cfg["baud"] == 1250000, "config --json: boot word 0x008B at 1.25 Mbaud")
expect_ok(["config", "set", "period=20", "led=on"], "period          20 ms")
expect_ok(["config", "set", "baud=115200"], "the board now speaks 115200 baud")
expect_rc(["config", "set", "bogus=1"], 2, "unknown key")
expect_rc(["config", "set", "period=12"], 2, "period")
expect_ok(["read", "ram", "0x0000", "2"], "8B 00")
expect_ok(["read", "rom", "0x000444", "4"], "0x000444")
expect_ok(["write", "ram", "0x0400", "12 34 56"], "wrote 3 bytes at 0x000400 in 1 frame")
expect_rc(["read", "ram", "0x0500", "2"], 2, "0x0500 is outside RAM (0x0000..0x048F)")
expect_rc(["read", "ram", "-5", "2"], 2, "-5 is outside RAM")  # names the memory asked for, not the ROM
expect_rc(["read", "ram", "0x0480", "32"], 2, "run outside RAM")
expect_rc(["read", "ics", "0", "2"], 2, "--ics")
out = expect_ok(["servo", "list"], "ICS")
check(len(out.strip().splitlines()) == 21, "servo list: 20 servos (a KHR-3HV) and a header")
states = json.loads(expect_ok(["--json", "servo", "get", "0", "3"], "["))
check([s["ics"] for s in states] == [0, 3] and states[0]["position"] == 7500, "servo get 0 3 --json")
expect_ok(["servo", "move", "0=8000@10", "1=7000"], "moving 2 servos")
expect_ok(["servo", "move", "--deg", "0=30"], "moving 1 servo")
expect_rc(["servo", "move", "0=20000"], 2, "outside 0..16383")
expect_rc(["servo", "move", "40=7500"], 2, "ICS")
# A slot the board lacks is the board's answer (exit 1), as for joints; a malformed item is exit 2.
expect_rc(["servo", "get", "30"], 1, "no servo allocated")
expect_rc(["servo", "move", "22=7500"], 1, "ICS 22 has no servo allocated")  # the board would ignore it
expect_rc(["servo", "free", "35"], 1, "ICS 35 has no servo allocated")
expect_rc(["servo", "hold", "0", "22"], 1, "ICS 22 has no servo allocated")
expect_rc(["servo", "move", "0=7500", "0=8000"], 2, "ICS 0 is given twice")
expect_rc(["servo", "free", "1", "1"], 2, "ICS 1 is given twice")
expect_ok(["servo", "free"], "freed 20 servos")
expect_ok(["servo", "hold", "1", "2"], "holding 2 servos")
expect_ok(["servo", "speed", "64"], "speed = 64 on 20 servos")
expect_ok(["servo", "stretch", "30", "5"], "stretch = 30 on 1 servo")
expect_rc(["servo", "stretch", "200"], 2, "outside 1..127")
sensors = json.loads(expect_ok(["--json", "sensors"], "{"))
check(len(sensors["ad"]) == 11 and 10.0 < sensors["battery_volts"] < 11.5, "sensors --json: 11 channels, battery")
expect_ok(["sensors"], "battery")
lines = expect_ok(["--json", "monitor", "--count", "3", "--hz", "20"], "sample").strip().splitlines()
check(len(lines) == 3 and json.loads(lines[2])["sample"] == 2, "monitor --count 3 --json: three samples")
# Ctrl-C ends an endless monitor cleanly: exit 0, every line printed whole.
p = subprocess.Popen([RCB4, "--json", "monitor", "--hz", "50"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
first = p.stdout.readline()
p.send_signal(signal.SIGINT)
rest, err = p.communicate(timeout=30)
check(p.returncode == 0 and json.loads(first)["sample"] == 0 and all(json.loads(l) for l in rest.splitlines()),
      f"monitor stops at Ctrl-C with exit 0 and whole lines (rc {p.returncode}, {err.strip()[:120]!r})")
expect_ok(["motion", "play", "2", "--wait", "--timeout", "10"], "done after")
expect_ok(["motion", "status"], "no motion running")
expect_ok(["motion", "stop"], "stopped")
expect_ok(["motion", "resume"], "resumed")
expect_rc(["motion", "play", "121"], 2, "outside 1..120")
expect_rc(["motion", "play", "120"], 1, "holds no motion")  # an erased slot: refused before anything changes
expect_ok(["motion", "status"], "no motion running")
expect_rc(["motion", "play", "1", "--layout", "9.9"], 2, "--layout")
expect_ok(["bench", "--count", "20"], "KHR-3HV cycle (20 joints")
rc, out, err = run("bench", "--count", "20", "--low-latency")
if os.access("/dev/cpu_dma_latency", os.W_OK):
    check(rc == 0 and "held at 0 us" in out, "bench --low-latency holds the PM QoS request")
else:
    check(rc == 3 and "cpu_dma_latency" in err, "bench --low-latency without permission: exit 3, says why")
def nobody():
    os.setgroups([])
    os.setgid(65534)
    os.setuid(65534)


def nobody_can_run():
    """True when user nobody reaches the tool (a clone under /root, mode 700, it does not)."""
    try:
        subprocess.run([RCB4, "--version"], capture_output=True, timeout=30, preexec_fn=nobody, cwd="/")
        return True
    except PermissionError:
        print("SKIPPED (the checks as user nobody): the tool is not reachable by user nobody here "
              f"({RCB4}: a clone under a private home); clone where others may read to run them")
        return False


as_nobody = os.geteuid() == 0 and nobody_can_run()
if as_nobody:  # as a user without root, as most users run it
    p = subprocess.run([RCB4, "ping"], capture_output=True, text=True, timeout=60, preexec_fn=nobody, cwd="/")
    # detect_baud opens the port, then the session opens it again: the first client's exclusive
    # mode (TIOCEXCL) must have ended with it, or the second open fails with EBUSY.
    check(p.returncode == 0 and "ACK" in p.stdout, "ping as a user without root (port reopened after detection)")
    p = subprocess.run([RCB4, "bench", "--count", "5", "--low-latency"], capture_output=True, text=True, timeout=60,
                       preexec_fn=nobody, cwd="/")
    check(p.returncode == 3 and "cpu_dma_latency" in p.stderr, "bench --low-latency without root: exit 3, says why")
rc, out, err = run("--trace", "ping")
check(rc == 0 and "-> 03 FE 01" in err and "<- 04 FE 06 08" in err and "ACK" in err, "--trace shows frames with meaning")

# ---- offline: decode / encode (golden frames by hand from protocol.md) -----------------------
expect_ok(["decode", "07 0F 00 0A 4C 1D 89"], "SINGLE ICS 0")
out = expect_ok(["decode"], "DATA", "decode from stdin", stdin="0A 00 20 00 00 00 00 00 02 2C\n05 00 8B 00 90\n")
check("MOV RAM[0x0000+2]" in out and "DATA" in out, "decode: a request then its data reply")
rc, out, err = run("decode", "07 0F 00 0A 4C 1D 88")
check(rc == 1 and "checksum" in out, "decode: bad checksum -> exit 1")
expect_rc(["decode", "0G"], 2, "hex digit")
expect_ok(["encode", "servo", "0", "7500", "10"], "07 0F 00 0A 4C 1D 89")
expect_ok(["encode", "ping"], "04 FE 06 08")
expect_ok(["encode", "read", "ram", "0x0000", "2"], "0A 00 20 00 00 00 00 00 02 2C")
expect_ok(["encode", "const", "10", "0=7500"], "0B 10 01 00 00 00 00 0A 4C 1D 8F")
expect_rc(["encode", "servo", "36", "7500"], 2, "ICS")
expect_ok(["list"], "")
# `list` on a fake sysfs tree: a KONDO adapter and an FTDI cable, as the kernel lays them out.
import tempfile
with tempfile.TemporaryDirectory() as root:
    for tty_name, usb, vid, pid, product, latency in [("ttyUSB0", "1-1", "165c", "0008", "Dual USB Adapter HS", 1),
                                                       ("ttyUSB1", "1-2", "0403", "6001", "FT232R USB UART", 16)]:
        iface = os.path.join(root, "devices/pci0000:00/usb1", usb, usb + ":1.0", tty_name)
        os.makedirs(iface)
        for f, v in [("idVendor", vid), ("idProduct", pid), ("product", product)]:
            with open(os.path.join(root, "devices/pci0000:00/usb1", usb, f), "w") as fh:
                fh.write(v + "\n")
        os.makedirs(os.path.join(root, "class/tty", tty_name))
        os.symlink(iface, os.path.join(root, "class/tty", tty_name, "device"))
        os.makedirs(os.path.join(root, "bus/usb-serial/devices", tty_name))
        with open(os.path.join(root, "bus/usb-serial/devices", tty_name, "latency_timer"), "w") as fh:
            fh.write(f"{latency}\n")
    p = subprocess.run([RCB4, "--json", "list"], capture_output=True, text=True, env={**os.environ, "RCB4_SYSFS_ROOT": root})
    ports = json.loads(p.stdout)
    check(len(ports) == 2 and ports[0]["path"] == "/dev/ttyUSB0" and ports[0]["kind"].startswith("KONDO")
          and ports[0]["latency_ms"] == 1 and ports[1]["kind"] == "FTDI USB serial" and ports[1]["latency_ms"] == 16,
          f"list: recognises KONDO 165C:0008 and FTDI on a fake sysfs ({p.stdout[:200]!r})")
expect_ok(["serve", "--help"], "--pty")

# ---- against the stand-in on a pty (not this project's board) --------------------------------
s = StandIn()
expect_ok(["--device", s.path, "ping"], "ACK from " + s.path)
expect_ok(["--device", s.path, "version"], "STAND-IN RCB-4 (python)")
expect_ok(["--device", s.path, "config"], "config 0x008B")
out = expect_ok(["--device", s.path, "--baud", "1250000", "servo", "list"], "7500")
check(len(out.strip().splitlines()) == 4, "stand-in: 3 allocated servos listed")
n = len(s.frames)
expect_ok(["--device", s.path, "--baud", "1250000", "servo", "move", "0=7500@10"], "moving 1 servo")
check(bytes.fromhex("0B 10 01 00 00 00 00 0A 4C 1D 8F") in s.frames[n:], "stand-in received the CONST frame KONDO's libraries send")
expect_ok(["--device", s.path, "--baud", "1250000", "write", "ram", "0x0400", "AA BB"], "wrote 2 bytes")
check(bytes.fromhex("09 00 02 00 04 00 AA BB 74") in s.frames, "stand-in received MOV literal -> RAM 0x0400")
expect_ok(["--device", s.path, "--baud", "1250000", "read", "ram", "0x0400", "2"], "AA BB")
rc, out, err = run("--device", s.path, "doctor")
check("[ ok ] board answers at" in out, "doctor --device: the board check passes")
if os.access("/dev/cpu_dma_latency", os.R_OK):
    check("[ -- ] CPU wake-up latency:" in out and "[FAIL] CPU" not in out,
          "doctor notes the CPU wake-up latency bound (a note, not a failure)")

silent = StandIn(silent=True)
t0 = time.monotonic()
rc, out, err = run("--device", silent.path, "--baud", "1250000", "--timeout", "50", "ping")
check(rc == 4 and "no reply" in err and time.monotonic() - t0 < 5, f"silent board: exit 4 within its deadline (rc {rc}, {time.monotonic() - t0:.2f} s)")
rc, out, err = run("--device", silent.path, "--timeout", "20", "ping")
check(rc == 4 and "no RCB-4 answered" in err, f"silent board, baud detection: exit 4 (rc {rc}: {err[:120]!r})")
expect_rc(["--device", "/dev/does-not-exist", "--baud", "115200", "ping"], 3, "no such device")

# ---- detection names the real cause, with its exit code, and --trace shows its frames --------
expect_rc(["--device", "/dev/does-not-exist", "ping"], 3, "No such file")
expect_rc(["--device", "/dev/null", "ping"], 3, "/dev/null: not a serial port")
rc, out, err = run("--device", "/dev/null", "ping")
check("Inappropriate ioctl" not in err and "rcb4 list" in err, f"/dev/null: the OS's words replaced, a hint ({err.strip()!r})")
# Global options after the command: exit 2, and the hint is the whole command line put right.
rc, out, err = run("doctor", "--device", "/dev/ttyUSB0")
check(rc == 2 and "put it before the command: rcb4 --device /dev/ttyUSB0 doctor" in err,
      f"doctor --device X: the hint keeps the device ({err.strip()!r})")
rc, out, err = run("servo", "list", "--json", "--device=/dev/x")
check(rc == 2 and "rcb4 --json --device=/dev/x servo list" in err, f"two globals after the command, = form ({err.strip()!r})")
# An option where a value belongs is not taken as the value.
for args in (["--device", "--baud", "115200", "ping"], ["--device", "--json", "ping"], ["--robot", "--json", "ping"]):
    rc, out, err = run(*args)
    check(rc == 2 and f"needs a value, and '{args[1]}' is an option" in err, f"rcb4 {' '.join(args)}: exit 2 ({err.strip()[:120]!r})")
# Malformed replies: each names what was wrong and what to do (README: Troubleshooting).
for mode, args, says, hint in [("short", ["servo", "list"], "reply length byte unexpected", "--trace"),
                               ("badsum", ["version"], "checksum", "parity")]:
    bad = StandIn(mode=mode)
    rc, out, err = run("--device", bad.path, "--baud", "115200", "--timeout", "50", *args)
    check(rc == 1 and says in err and hint in err, f"a {mode} board, {' '.join(args)}: exit 1, '{says}' with a hint ({err.strip()!r})")
for mode, rc_wanted, says in [("nack", 1, "NACK"), ("badsum", 1, "checksum"), ("echo", 1, "echoes")]:
    bad = StandIn(mode=mode)
    rc, out, err = run("--device", bad.path, "--timeout", "20", "ping")
    check(rc == rc_wanted and says in err, f"detection against a {mode} board: exit {rc_wanted}, says {says!r} (rc {rc}: {err[:160]!r})")
    rc, out, err = run("--device", bad.path, "--baud", "115200", "--timeout", "20", "ping", "--count", "3")
    check(rc == rc_wanted and says in err, f"--baud given, a {mode} board: exit {rc_wanted}, says {says!r} (rc {rc}: {err[:160]!r})")
expect_rc(["--device", "", "ping"], 2, "--device is empty")
if as_nobody:  # a port the user may not open (the stand-in's pty belongs to root, mode 0620)
    p = subprocess.run([RCB4, "--device", s.path, "ping"], capture_output=True, text=True, timeout=60,
                       preexec_fn=nobody, cwd="/")
    check(p.returncode == 3 and "Permission denied" in p.stderr and "dialout" in p.stderr,
          f"detection without permission: exit 3, says so, with the fix ({p.returncode}: {p.stderr[:160]!r})")
expect_rc(["--baud", "9600", "ping"], 2, "115200, 625000 or 1250000")
lossy = StandIn(mode="drop")
rc, out, err = run("--device", lossy.path, "--baud", "115200", "--timeout", "30", "ping", "--count", "4")
check(rc == 0 and "retries after" in out, f"ping --count on a lossy line says it retried ({out[-160:]!r})")
rc, out, err = run("--json", "--device", lossy.path, "--baud", "115200", "--timeout", "30", "ping", "--count", "4")
check(rc == 0 and json.loads(out)["retries"] > 0 and json.loads(out)["timeouts"] > 0, f"ping --json counts retries ({out!r})")
rc, out, err = run("--device", s.path, "--trace", "ping")
check(rc == 0 and "-> 03 FE 01" in err and "<- 04 FE 06 08" in err, f"--trace shows the detection's frames ({err[:200]!r})")

# ---- a pty that another program configured first (a C client's raw 8E1 at 115200) opens -----
import termios
for i in range(10):
    fd = os.open(s.path, os.O_RDWR | os.O_NOCTTY)
    attrs = termios.tcgetattr(fd)
    tty.setraw(fd)
    attrs = termios.tcgetattr(fd)
    attrs[2] |= termios.PARENB | termios.CS8 | termios.CLOCAL | termios.CREAD
    attrs[4] = attrs[5] = termios.B115200
    try:
        termios.tcsetattr(fd, termios.TCSANOW, attrs)  # a pty drops PARENB: glibc may say EINVAL
    except termios.error:
        pass
    os.close(fd)
    rc, out, err = run("--device", s.path, "ping")
    if rc != 0:
        break
check(rc == 0 and "ACK" in out, f"a pty left raw 8E1 by another program answers, 10 times in a row (rc {rc}: {err[:160]!r})")

# ---- issue 12: options reach their command, help per command, JSON everywhere -----------------
t0 = time.monotonic()
rc, out, err = run("motion", "play", "2", "--wait", "--timeout", "0.2")
check(rc == 4 and "motion 2 still running after 0.2 s" in err and "program counter" in err and time.monotonic() - t0 < 5,
      f"motion play --wait --timeout 0.2: the per-command timeout reaches the wait, which says the motion runs on (rc {rc}: {err[:200]!r})")
rc, out, err = run("motion", "wait", "--timeout", "5")
check(rc == 0 and "done after" in out, f"motion wait --timeout 5 (seconds, not the global allowance) (rc {rc}: {err[:160]!r})")
rc, out, err = run("--json", "motion", "play", "2", "--wait", "--timeout", "10")
j = json.loads(out) if rc == 0 else {}
check(rc == 0 and j.get("played") == 2 and j["state"]["running"] is False and out.count("\n") == 1,
      f"--json motion play --wait: one object (rc {rc}: {out[:200]!r})")
rc, out, err = run("servo", "--help")
check(rc == 0 and "Usage: rcb4 servo" in out and "move" in out and "monitor" not in out, "servo --help is the servo command's own help")
rc, out, err = run("motion", "play", "--help")
check(rc == 0 and "Usage: rcb4 motion play" in out and "--release" in out and "HeartToHeart4 version" in out,
      "motion play --help explains --release and --layout")
rc, out, err = run("--version")
check(rc == 0 and out.startswith("rcb4 "), f"--version ({out!r})")
rc, out, err = run("bogus")
check(rc == 2 and "unknown command 'bogus'" in err and "rcb4 bogus --help" not in err, f"rcb4 bogus ({err!r})")
rc, out, err = run("ping", "--json")
check(rc == 2 and "global option" in err and "rcb4 --json ping" in err, f"a global option after the command: exit 2, says where it goes ({err!r})")
p = subprocess.run([RCB4, "ping"], capture_output=True, text=True, env={**os.environ, "RCB4_DEVICE": "/dev/does-not-exist"})
check(p.returncode == 3 and "/dev/does-not-exist" in p.stderr, f"RCB4_DEVICE names the default device ({p.stderr[:120]!r})")
p = subprocess.run([RCB4, "ping"], capture_output=True, text=True, env={**os.environ, "RCB4_DEVICE": ""})
check(p.returncode == 2 and "RCB4_DEVICE is set but empty" in p.stderr, "an empty RCB4_DEVICE is a usage error, not the virtual board")
p = subprocess.run([RCB4, "--device", s.path, "ping"], capture_output=True, text=True, env={**os.environ, "RCB4_DEVICE": "/dev/does-not-exist"})
check(p.returncode == 0, "--device wins over RCB4_DEVICE")
# Errors are JSON under --json: one object on stdout with the exit code.
for args, code in [(["--json", "--device", "/dev/does-not-exist", "ping"], 3), (["--json", "servo", "move", "0=20000"], 2),
                   (["--json", "bogus"], 2), (["--json", "--device", silent.path, "--baud", "115200", "--timeout", "20", "ping"], 4),
                   (["--json", "motion", "play", "120"], 1)]:
    rc, out, err = run(*args)
    try:
        j = json.loads(out)
    except ValueError:
        j = {}
    check(rc == code and j.get("exit") == code and j.get("error"), f"{' '.join(args[1:])}: JSON error with exit {code} (rc {rc}: {out[:160]!r})")
doc = json.loads(run("--json", "--device", s.path, "doctor")[1])
check(any(c["ok"] and c["check"].startswith("board answers") for c in doc["checks"]) and "problems" in doc, "doctor --json: an object of checks")
d = json.loads(run("--json", "decode", "07 0F 00 0A 4C 1D 89")[1])
check(d["frames"][0]["kind"] == "request" and "SINGLE" in d["frames"][0]["meaning"] and d["bad"] == 0, "decode --json: objects, not strings of text")
line = json.loads(run("--json", "monitor", "--count", "1")[1])
check(len(line["ad"]) == 11 and len(line["pa"]) == 4 and line["time"] > 1.7e9 and "elapsed_s" in line, "monitor --json: AD0..AD10, PA1..PA4 and a timestamp")
# monitor by the profile's joint names: every joint the board has, or those --joints names.
check(len(line.get("joints", {})) == 20 and isinstance(line["joints"].get("left_knee"), float),
      f"monitor --json: the KHR-3HV's 20 joints by name, in degrees ({line.get('joints')})")
line = json.loads(run("--json", "monitor", "--count", "1", "--joints", "left_arm", "head_yaw")[1])
check(set(line.get("joints", {})) == {"left_shoulder_pitch", "left_shoulder_roll", "left_elbow_yaw", "left_elbow_pitch", "head_yaw"},
      f"monitor --joints left_arm head_yaw: those joints only ({sorted(line.get('joints', {}))})")
rc, out, err = run("monitor", "--count", "1", "--joints", "left_knee")
check(rc == 0 and "left_knee" in out and "ICS" not in out, f"monitor shows joint names ({rc}: {out.strip()[-200:]!r})")
rc, out, err = run("monitor", "--count", "1", "--joints", "left_kneee")
check(rc == 2 and "left_kneee" in err, f"monitor --joints with an unknown joint: exit 2 ({rc}: {err.strip()!r})")

# ---- decode: the tool's own trace, invalid requests, the checksum it should have had -----------
rc, out, err = run("--trace", "servo", "get", "0")
rc2, out2, err2 = run("decode", stdin=err)
check(rc == 0 and rc2 == 0 and "request" in out2 and "reply" in out2 and "DATA" in out2,
      f"decode reads the lines of --trace (rc {rc2}: {out2[:300]!r} {err2[:200]!r})")
rc, out, err = run("decode", "07 0F 24 0A 4C 1D AD")  # SINGLE to ICS 36, checksum right
check(rc == 1 and "invalid request" in out and "DATA" not in out, f"decode: SINGLE to ICS 36 is an invalid request ({out!r})")
rc, out, err = run("decode", "07 0F 00 0A 4C 1D 88")
check(rc == 1 and "0x88" in out and "0x89" in out, f"decode: a bad checksum shows the one expected ({out!r})")

# ---- broken boards (Python stand-ins): each failure named, with its exit code -----------------
empty = StandIn(mode="empty")
for args in [["servo", "list"], ["servo", "get", "0"], ["servo", "move", "0=7500"], ["servo", "free"]]:
    rc, out, err = run("--device", empty.path, "--baud", "1250000", *args)
    check(rc == 1 and "no servo allocated" in err and "7500" not in out,
          f"empty allocation table: {' '.join(args)} exits 1 and says so, no numbers (rc {rc}: {out[:80]!r} {err[:120]!r})")
short = StandIn(mode="short")
rc, out, err = run("--device", short.path, "--baud", "1250000", "read", "ram", "0", "4")
check(rc == 1, f"replies of the wrong length: exit 1, a board/line problem (rc {rc}: {err[:200]!r})")
rc, out, err = run("--device", empty.path, "--baud", "1250000", "motion", "play", "3", "--layout", "2.2")
check(rc == 1 and "motion 3 (0x001B80) holds no motion" in err, f"stand-in with an erased ROM: motion play refused (rc {rc}: {err[:160]!r})")
rc, out, err = run("--device", empty.path, "--baud", "1250000", "motion", "play", "3")
check(rc == 1 and "cannot tell which HeartToHeart4 layout" in err,
      f"stand-in with an erased ROM: its layout is not guessed (rc {rc}: {err[:160]!r})")
late = StandIn(mode="late")
rc, out, err = run("--device", late.path, "--baud", "115200", "--timeout", "1000", "ping")
check(rc == 0 and " ms" in out and " us" not in out, f"a late reply is timed in ms, not 300000 us ({out!r})")
rc, out, err = run("--device", late.path, "--baud", "115200", "--timeout", "50", "ping")
check(rc == 4 and "deadline" in err, f"replies later than the allowance: exit 4 (rc {rc}: {err[:160]!r})")
import tempfile as _tf
with _tf.TemporaryDirectory() as tmp:
    # trim set --persist on a board that dies between the RAM write and the ROM write: the error
    # says the RAM already holds the new trim (the stand-in has ICS 0-2; a one-joint robot on ICS 1).
    robot = os.path.join(tmp, "arm.yaml")
    open(robot, "w").write("robot: arm\njoints:\n  elbow: {ics: 1, lower: -90, upper: 90}\n")
    for die_after in range(1, 8):
        dying = StandIn(mode="die", die_after=die_after)
        rc, out, err = run("--device", dying.path, "--baud", "1250000", "--timeout", "30", "--robot", robot,
                           "trim", "set", "elbow=2", "--persist")
        ram_written = dying.ram[0x0090 + 20 + 2:0x0090 + 20 + 4] == (59).to_bytes(2, "little")
        if ram_written:
            break
    check(ram_written and rc == 4 and "already written: RAM elbow +59; ROM none" in err,
          f"trim set --persist interrupted after the RAM write says RAM changed (rc {rc}: {err.strip()[:200]!r})")
with _tf.TemporaryDirectory() as tmp:
    image = os.path.join(tmp, "rom.bin")
    with open(image, "wb") as f:
        f.write(bytes(range(256)) * 234 + bytes(96))  # 60,000 bytes
    dying = StandIn(mode="die", die_after=30)
    rc, out, err = run("--device", dying.path, "--baud", "1250000", "--timeout", "30", "write", "rom", "0x10000", "--file", image)
    check(rc == 4 and "write stopped after" in err and "of 60000 bytes" in err and "0x010000.." in err,
          f"a board that dies mid-write: says how much was written, and where (rc {rc}: {err[:300]!r})")
    good = StandIn()
    rc, out, err = run("--device", good.path, "--baud", "1250000", "write", "rom", "0x10000", "--file", image)
    check(rc == 0 and "wrote 60000 bytes" in out and "%" not in err, f"write --file: 60,000 bytes, no progress in a pipe (rc {rc}: {err[-200:]!r})")
    # On a terminal, the same transfer shows its progress on stderr.
    import pty as _pty
    master, slave = _pty.openpty()
    p = subprocess.Popen([RCB4, "read", "rom", "0", "0x8000", "--output", os.path.join(tmp, "out.bin")], stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    shown = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:
            break
        if not chunk:
            break
        shown += chunk
    p.wait(timeout=60)
    check(p.returncode == 0 and b"reading ROM" in shown and b"%" in shown and os.path.getsize(os.path.join(tmp, "out.bin")) == 0x8000,
          f"read --output on a terminal shows progress and saves the bytes (rc {p.returncode}: {shown[-120:]!r})")
    rc, out, err = run("serve", "--pty", "--rom", "/proc/no-such-dir/rom.bin")
    check(rc == 3 and "cannot be written" in err, f"serve --rom into an unwritable place fails at start (rc {rc}: {err[:160]!r})")

# ---- smaller things the trial found ----------------------------------------------------------
expect_ok(["write", "ram", "0x0400", "12"], "wrote 1 byte at 0x000400 in 1 frame")
expect_rc(["servo", "move", "--deg", "3=136"], 2, "beyond the servo's turn")
rc, out, err = run("servo", "move", "3=12000")
check(rc == 0 and "warning" in err and "3500..11500" in err, "servo move beyond the servo's turn (raw) warns")
expect_rc(["motion", "play", "2", "--layout", "2.0"], 1, "another")  # 2.0's slot 2 lands inside 2.2's motion 2
import socket as _socket
blocker = _socket.socket()
blocker.bind(("127.0.0.1", 0))
blocker.listen()
rc, out, err = run("serve", "--tcp", f"127.0.0.1:{blocker.getsockname()[1]}")
check(rc == 3 and "cannot serve" in err and "/usr/include" not in err and ".hpp" not in err, f"serve on a port in use: exit 3, no source path ({err!r})")
blocker.close()
srv = subprocess.Popen([RCB4, "serve", "--tcp", "127.0.0.1:0"], stdout=subprocess.PIPE, text=True)
where = srv.stdout.readline().strip()
rc, out, err = run("--device", "tcp:" + where, "bench", "--count", "5")
check(rc == 0 and "line rate unknown" in out and "wire limit" not in out, f"bench over TCP without --baud claims no wire limit ({out[:200]!r})")
rc, out, err = run("--device", "tcp:" + where, "--baud", "1250000", "bench", "--count", "5")
check(rc == 0 and "wire limit" in out, "bench over TCP with --baud has its wire limit")
rc, out, err = run("--json", "--device", "tcp:" + where, "bench", "--count", "5")
b = json.loads(out) if rc == 0 else {}
check(rc == 0 and b.get("paced", "absent") is None and b.get("byte_time_measured") is True and b.get("baud") is None,
      f"bench --json over TCP, rate unknown: paced null, the byte time measured ({b.get('paced', 'absent')}, {b.get('byte_time_ns')})")
# One client at a time: a second one is closed at once (it waited with no reply, to its timeout).
first = _socket.create_connection(tuple([where.split(":")[0], int(where.split(":")[1])]))
first.sendall(bytes([0x03, 0xFE, 0x01]))
check(first.recv(4) == bytes([0x04, 0xFE, 0x06, 0x08]), "the first TCP client is served")
t0 = time.monotonic()
rc, out, err = run("--device", "tcp:" + where, "--baud", "1250000", "--timeout", "2000", "ping")
check(rc == 3 and ("closed" in err or "reset by peer" in err) and time.monotonic() - t0 < 1.8,  # not its 2 s timeout
      f"a second TCP client is closed after 250 ms, not left unanswered (rc {rc} in {time.monotonic() - t0:.2f} s: {err.strip()!r})")
first.close()  # and a client right after it (no pause) is served: the server waits for the first to go
expect_ok(["--device", "tcp:" + where, "--baud", "1250000", "ping"], "ACK")
srv.terminate()
srv.wait(timeout=10)

# A motion on a board without its servos ends (it stopped at its first pose, to the timeout).
none = subprocess.Popen([RCB4, "serve", "--pty", "--servos", "0"], stdout=subprocess.PIPE, text=True)
t0 = time.monotonic()
rc, out, err = run("--device", none.stdout.readline().strip(), "motion", "play", "2", "--wait", "--timeout", "10")
check(rc == 0 and "done after" in out and time.monotonic() - t0 < 6, f"serve --servos 0: motion play 2 --wait ends ({rc}, {time.monotonic() - t0:.1f} s, {err.strip()!r})")
none.terminate()
none.wait(timeout=10)
# serve --strict-baud: a frame at another rate than the board's gets no reply, as on a real line,
# so a client's baud handling can be tested (detection finds the board's rate; a wrong --baud fails).
strict = subprocess.Popen([RCB4, "serve", "--pty", "--strict-baud"], stdout=subprocess.PIPE, text=True)
sp = strict.stdout.readline().strip()
rc, out, err = run("--device", sp, "--baud", "115200", "--timeout", "50", "ping")
check(rc == 4 and "no reply" in err, f"--strict-baud: a client at 115200 to a 1.25 Mbaud board gets no reply, exit 4 ({rc})")
rc, out, err = run("--json", "--device", sp, "config")
check(rc == 0 and json.loads(out).get("baud") == 1250000, f"baud detection finds the board's rate ({out.strip()[:100]!r})")
rc, out, err = run("--device", sp, "config", "set", "baud=115200")
rc2, out2, err2 = run("--device", sp, "--baud", "1250000", "--timeout", "50", "ping")
rc3, out3, err3 = run("--device", sp, "--baud", "115200", "ping")
check(rc == 0 and rc2 == 4 and rc3 == 0, f"after config set baud=115200 only 115200 is answered ({rc}, {rc2}, {rc3})")
strict.terminate()
strict.wait(timeout=10)
expect_rc(["serve", "--tcp", "127.0.0.1:0", "--strict-baud"], 2, "--strict-baud requires --pty")

# SIGINT ends serve at once, also while a reply waits out a long --latency (it waited it out).
slow_srv = subprocess.Popen([RCB4, "serve", "--pty", "--latency", "5000000"], stdout=subprocess.PIPE, text=True)
slow_dev = slow_srv.stdout.readline().strip()
asker = subprocess.Popen([RCB4, "--device", slow_dev, "--baud", "1250000", "--timeout", "100", "ping"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
time.sleep(0.3)
t0 = time.monotonic()
slow_srv.send_signal(signal.SIGINT)
slow_srv.wait(timeout=10)
check(slow_srv.returncode == 0 and time.monotonic() - t0 < 2.5,  # not the 5 s latency (loaded sanitizer builds are slow)
      f"serve stops at SIGINT while a reply is delayed ({slow_srv.returncode}, {time.monotonic() - t0:.2f} s)")
asker.wait(timeout=10)

# serve --period: the board boots with that output period (HTH4's sample projects use 15 ms).
p15 = subprocess.Popen([RCB4, "serve", "--pty", "--period", "15"], stdout=subprocess.PIPE, text=True)
rc, out, err = run("--json", "--device", p15.stdout.readline().strip(), "config")
check(rc == 0 and json.loads(out)["period_ms"] == 15, f"serve --period 15: the config word says 15 ms ({out.strip()[:80]!r})")
p15.terminate()
p15.wait(timeout=10)
expect_rc(["serve", "--pty", "--period", "12"], 2, "--period")

# serve --turn: a hand turns head_yaw (ICS 0, free at boot) 500 counts and back every 100 ms, each
# turn printed with its CLOCK_MONOTONIC time (time.monotonic() here); the board shows the position.
hand = subprocess.Popen([RCB4, "serve", "--pty", "--turn", "0:100"], stdout=subprocess.PIPE, text=True)
hand_path = hand.stdout.readline().strip()
t0 = time.monotonic()
first, second = hand.stdout.readline().split(), hand.stdout.readline().split()
check(first[:3] == ["turned", "ICS", "0"] and second[:3] == ["turned", "ICS", "0"]
      and int(first[4]) == int(second[4]) + 500 and t0 <= float(first[6]) < float(second[6]) <= time.monotonic()
      and 0.09 <= float(second[6]) - float(first[6]) < 0.5,  # 100 ms apart, late under a loaded sanitizer build
      f"serve --turn 0:100: 500 counts one way, then back, 100 ms apart, at monotonic times ({first}, {second})")
rc, out, err = run("--json", "--device", hand_path, "servo", "get", "0")
now_at = hand.stdout.readline().split()  # the turn after the read: the read saw the one before it
check(rc == 0 and json.loads(out)[0]["position"] in (int(first[4]), int(second[4])),
      f"the board shows the turned position ({out.strip()[:100]!r}, {now_at})")
hand.send_signal(signal.SIGINT)
check(hand.wait(timeout=10) == 0, f"serve --turn ends at SIGINT with 0 ({hand.returncode})")
hand = subprocess.Popen([RCB4, "--json", "serve", "--pty", "--turn", "0:50"], stdout=subprocess.PIPE, text=True)
hand.stdout.readline()
turn = json.loads(hand.stdout.readline())
check(turn["turned"] == 0 and turn["to"] == 8000 and turn["at"] <= time.monotonic(),
      f"serve --turn with --json: an object per turn ({turn})")
hand.send_signal(signal.SIGINT)
hand.wait(timeout=10)
expect_rc(["serve", "--pty", "--turn", "40:100"], 2, "--turn ICS")
expect_rc(["serve", "--pty", "--turn", "0"], 2, "expected ICS:MS")
expect_rc(["serve", "--pty", "--turn", "3:0"], 2, "--turn MS")
expect_rc(["serve", "--pty", "--silent", "3", "--turn", "3:100"], 2, "no answering servo at ICS 3")

# monitor faster than the link: says so once on stderr, every line still whole JSON.
paced = subprocess.Popen([RCB4, "serve", "--pty", "--pace", "--latency", "1000"], stdout=subprocess.PIPE, text=True)
rc, out, err = run("--json", "--device", paced.stdout.readline().strip(), "--baud", "1250000", "monitor", "--hz", "1000",
                   "--count", "20")
check(rc == 0 and err.count("1000 Hz asked, the board and link give") == 1 and len(out.splitlines()) == 20
      and all(json.loads(l)["sample"] >= 0 for l in out.splitlines()),
      f"monitor --hz 1000 on a slower link warns once ({rc}, {err.strip()[:120]!r})")
paced.terminate()
paced.wait(timeout=10)

# ---- found by a newcomer trial ---------------------------------------------------------------
# A late reply to a request the previous program gave up on must not answer the next program's.
slow = subprocess.Popen([RCB4, "serve", "--pty", "--latency", "150000"], stdout=subprocess.PIPE, text=True)
slow_path = slow.stdout.readline().strip()
wrong = 0
first = []
for i in range(3):
    rc_a, _, err_a = run("--device", slow_path, "--baud", "1250000", "--timeout", "20", "read", "ram", "0", "4")
    first.append((rc_a, err_a.strip().splitlines()[0] if err_a.strip() else ""))
    rc, out, err = run("--device", slow_path, "--baud", "1250000", "--timeout", "1000", "read", "ram", "0x400", "4")
    if rc == 0 and "8B 00" in out:
        wrong += 1
# The impatient run fails every time: no answer in time (4), or, when a late reply of the run
# before reaches it after its flush, a reply of the wrong shape refused (1); never data (0).
check(all(rc_a in (1, 4) for rc_a, _ in first) and wrong == 0,
      f"a stale reply left by a previous run never answers the next run ({wrong} wrong of 3; the 20 ms runs: {first})")
slow.terminate()
slow.wait(timeout=10)
p = subprocess.run([RCB4, "encode", "ping"], capture_output=True, text=True, env={**os.environ, "RCB4_DEVICE": ""})
check(p.returncode == 0 and "04 FE 06 08" in p.stdout, "an empty RCB4_DEVICE does not block commands that open no device")
expect_rc(["--device", "tcp:127.0.0.1:99999", "ping"], 2, "99999 is outside")
expect_rc(["--device", "tcp:127.0.0.1", "ping"], 2, "expected tcp:HOST:PORT")
expect_rc(["motion", "play", "2", "--timeout", "5"], 2, "--timeout requires --wait")
t0 = time.monotonic()
expect_rc(["read", "rom", "0", "0x40000", "--output", "/proc/no-such-dir/x.bin"], 3, "cannot create it")
check(time.monotonic() - t0 < 3, "read --output into a bad path fails before the transfer")
rc, out, err = run("--json", "--device", "tcp:" + "127.0.0.1:1", "--baud", "1250000", "config", "set", "baud=625000")
check(rc != 0, "config set baud= over TCP does not claim the bridge followed")

# ---- rcb4 urdf: the robot for rviz and MoveIt, checked by Debian's URDF parser (liburdfdom-tools) ----
import shutil  # noqa: E402
import tempfile  # noqa: E402
for robot, root, joints in (("khr-3hv", "pelvis", 20), ("kxr-l2", "torso", 17)):
    rc, out, err = run("--robot", robot, "urdf")
    check(rc == 0 and out.count('type="revolute"') == joints, f"rcb4 --robot {robot} urdf: {joints} joints ({rc}: {err.strip()!r})")
    if shutil.which("check_urdf"):
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as f:
            f.write(out)
        p = subprocess.run(["check_urdf", f.name], capture_output=True, text=True)
        os.unlink(f.name)
        check(p.returncode == 0 and "Successfully Parsed XML" in p.stdout and f"root Link: {root}" in p.stdout,
              f"check_urdf parses it, root {root} ({p.returncode}: {p.stdout[:120]!r} {p.stderr[:200]!r})")
    else:
        check(False, "check_urdf (liburdfdom-tools) is installed: cmake/install-deps.sh installs it")
expect_rc(["--robot", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "profiles", "missing.yaml"),
           "urdf"], 2, "missing.yaml")
with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
    f.write("robot: bare\njoints:\n  a: {ics: 1, lower: -10, upper: 10}\n")
expect_rc(["--robot", f.name, "urdf"], 2, "has no kinematics")
os.unlink(f.name)

# ---- serve --hand: a script poses a freed joint, as a person would -------------------------------
hand = subprocess.Popen([RCB4, "serve", "--pty", "--hand"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                        stderr=subprocess.PIPE, text=True, bufsize=1)
hand_dev = hand.stdout.readline().strip()
hand.stdin.write("left_knee 30\n")
hand.stdin.flush()
err_line = hand.stderr.readline()
check("left_knee: its servo holds its position: free it first" in err_line, f"--hand leaves a held joint alone ({err_line!r})")
rc, out, err = run("--device", hand_dev, "joint", "free", "left_knee")
hand.stdin.write("left_knee 30\n")
hand.stdin.flush()
said = hand.stdout.readline()
rc, out, err = run("--json", "--device", hand_dev, "joint", "list")
knee = [j for j in json.loads(out) if j["name"] == "left_knee"][0] if rc == 0 else {}
check("hand turned left_knee to 30" in said and abs(knee.get("degrees", 99) - 30) < 0.5,
      f"--hand turns a freed joint, and the board measures it there ({said!r}, {knee.get('degrees')})")
hand.stdin.write("no_such 3\n")
hand.stdin.flush()
check("expected JOINT DEGREES" in hand.stderr.readline(), "--hand: a line that names no joint is answered on stderr")
hand.stdin.close()
hand.terminate()
check(hand.wait(timeout=10) == 0, "serve --hand ends on SIGTERM with 0")
# From a named pipe, as docs/virtual-board.md shows: one echo after another is read.
with tempfile.TemporaryDirectory() as d:
    fifo = os.path.join(d, "hand")
    os.mkfifo(fifo)
    hand = subprocess.Popen(f'exec "{RCB4}" serve --pty --hand < "{fifo}"', shell=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, bufsize=1)
    for deg in (10, 20):
        with open(fifo, "w") as w:
            w.write(f"left_knee {deg}\n")
    lines = [hand.stderr.readline() for _ in range(2)]
    check(all("left_knee: its servo holds its position" in x for x in lines),
          f"--hand from a named pipe answers each writer's line ({lines!r})")
    hand.terminate()
    check(hand.wait(timeout=10) == 0, "and ends on SIGTERM with 0")

finish()
