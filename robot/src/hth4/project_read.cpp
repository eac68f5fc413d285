// rcb4 — reading an HTH4 project (.h4p) into a project value (hth4-files.md §2), every element
// checked with its line, then the whole checked as a board would run it (project_check.cpp).
// SPDX-License-Identifier: BSL-1.0
#include "project_check.hpp"
#include "xml.hpp"

#include <map>

namespace rcb4::robot::hth4 {

namespace {

using detail::xml_in;

std::vector<std::uint8_t> bytes_of(const xml_in& x, const pugi::xml_node& n, const char* name, std::size_t count) {
  const auto e = x.need(n, name);
  std::vector<std::uint8_t> out;
  for (auto b = e.first_child(); b; b = b.next_sibling()) {
    if (std::string_view(b.name()) != "unsignedByte")
      x.fail(b, std::string("<") + name + "> holds <unsignedByte> only");
    out.push_back(static_cast<std::uint8_t>(x.integer_of(b, 0, 255)));
  }
  if (out.size() != count) x.fail(e, "has " + std::to_string(out.size()) + " bytes, not " + std::to_string(count));
  return out;
}

/** The value child @p element of @p n names among @p names, else an error "'X' is not WHAT (A, B)". */
template <class E>
E named(const xml_in& x, const pugi::xml_node& n, const char* element,
        std::initializer_list<std::pair<std::string_view, E>> names, const char* what) {
  const auto e = x.need(n, element);
  std::string list;
  for (const auto& [name, value] : names) {
    if (name == e.child_value()) return value;
    list += (list.empty() ? "" : ", ") + std::string(name);
  }
  x.fail(e, std::string("'").append(e.child_value()).append("' is not ").append(what).append(" (" + list + ")"));
}

compare_type compare_of(const xml_in& x, const pugi::xml_node& n) {
  const auto e = x.need(n, "CompareType");
  const auto c = compare_from(e.child_value());
  if (!c)
    x.fail(e, "'" + std::string(e.child_value()) +
                  "' is not a compare type (Equals, NotEquals, GreaterThan, LessThan, GreaterThanOrEqualTo, "
                  "LessThanOrEqualTo, Zero, None)");
  return *c;
}

/** The Value of a DictionaryEntry, with its xsi:type checked; null when the entry has none. */
pugi::xml_node value_of(const xml_in& x, const pugi::xml_node& entry, std::string_view type, bool optional = false) {
  const auto v = entry.child("Value");
  if (!v) {
    if (optional) return v;
    x.fail(entry, "has no <Value>");
  }
  if (v.attribute("xsi:nil").as_bool()) {
    if (optional) return {};
    x.fail(v, "is nil");
  }
  x.need_type(v, type);
  return v;
}

struct lines {
  std::vector<pugi::xml_node> motions, servos, priority;
  std::vector<std::vector<pugi::xml_node>> frames;
  pugi::xml_node root, startup;
};

motion_entry read_motion(const xml_in& x, const pugi::xml_node& entry, std::size_t i, lines& at) {
  char key[8];
  std::snprintf(key, sizeof key, "M%03zu", (i + 1) % 1000);
  const auto k = x.need(entry, "Key");
  if (std::string_view(k.child_value()) != key)
    x.fail(k, "is '" + std::string(k.child_value()) + "', not '" + key + "' (the motions are M001..M120 in order)");
  const auto v = value_of(x, entry, "Motion");
  at.motions.push_back(v);
  motion_entry m;
  m.number = static_cast<unsigned>(x.integer(v, "Number", 0, 119));
  m.name = x.text(v, "Name");
  m.date = x.text(v, "Date");
  m.buttons = static_cast<std::uint16_t>(x.integer(v, "ButtonData", 0, 0xFFFF));
  m.compare = compare_of(x, v);
  const auto data = x.need(v, "MotionData");
  at.frames.emplace_back();
  for (auto f = data.first_child(); f; f = f.next_sibling()) {
    if (std::string_view(f.name()) != "anyType") x.fail(f, "<MotionData> holds <anyType> frames only");
    x.need_type(f, "xsd:string");
    auto bytes = parse_frame_text(f.child_value());
    if (!bytes)
      x.fail(f, "'" + std::string(std::string_view(f.child_value()).substr(0, 60)) +
                    "' is not a frame (hex byte pairs separated by single spaces)");
    m.frames.push_back(std::move(*bytes));
    at.frames.back().push_back(f);
  }
  m.address = static_cast<std::uint32_t>(x.integer(v, "Address", 0, 0x3FFFF));
  if (const auto kc = v.child("KeyCode")) m.key_code = kc.child_value();
  return m;
}

servo_entry read_servo(const xml_in& x, const pugi::xml_node& entry) {
  const auto v = value_of(x, entry, "ServoItem");
  servo_entry s;
  s.name = x.text(v, "Name");
  if (std::string_view(x.text(entry, "Key")) != s.name)
    x.fail(x.need(entry, "Key"), "is '" + x.text(entry, "Key") + "', not the servo's Name '" + s.name + "'");
  s.count = static_cast<unsigned>(x.integer(v, "Count", 0, 255));
  s.rom_address = static_cast<std::uint32_t>(x.integer(v, "RomAddress", 0, 0x3FFFF));
  s.ram_address = static_cast<std::uint32_t>(x.integer(v, "RamAddress", 0, 0xFFFF));
  s.mode =
      named<servo_mode>(x, v, "Mode", {{"Normal", servo_mode::normal}, {"None", servo_mode::none}}, "a servo mode");
  s.port = named<servo_port>(x, v, "Port", {{"SIO1", servo_port::sio1}, {"SIO2", servo_port::sio2}}, "a servo port");
  s.device_number = static_cast<unsigned>(x.integer(v, "DeviceNumber", 0, 35));
  s.code = static_cast<unsigned>(x.integer(v, "Code", 0, 255));
  s.id = static_cast<unsigned>(x.integer(v, "ID", 0, 31));
  s.trim = static_cast<int>(x.integer(v, "Trim", -32768, 32767));
  s.position = static_cast<int>(x.integer(v, "Position", 0, 65535));
  s.mixing1_address = static_cast<std::uint16_t>(x.integer(v, "Mixing1Address", 0, 0xFFFF));
  s.mixing1_rate = static_cast<int>(x.integer(v, "Mixing1Rate", -32768, 32767));
  s.mixing2_address = static_cast<std::uint16_t>(x.integer(v, "Mixing2Address", 0, 0xFFFF));
  s.mixing2_rate = static_cast<int>(x.integer(v, "Mixing2Rate", -32768, 32767));
  if (const auto d = v.child("DisplayRate")) s.display_rate = d.child_value();
  if (const auto l = v.child("Location")) {
    s.x = static_cast<int>(x.integer(l, "X", -100000, 100000));
    s.y = static_cast<int>(x.integer(l, "Y", -100000, 100000));
  }
  s.group_xml = xml_in::raw(v.child("Group"));
  s.fore_color_xml = xml_in::raw(v.child("ForeColor"));
  s.back_color_xml = xml_in::raw(v.child("BackColor"));
  return s;
}

kri3_block read_kri3(const xml_in& x, const pugi::xml_node& n) {
  kri3_block k;
  k.name = x.text(n, "Name");
  const auto u = [&](const char* name, long long hi) { return static_cast<unsigned>(x.integer(n, name, 0, hi)); };
  k.count = u("Count", 255);
  k.rom_address = u("RomAddress", 0x3FFFF);
  k.ram_address = u("RamAddress", 0xFFFF);
  k.device_number = u("DeviceNumber", 255);
  k.code = u("Code", 255);
  k.id = u("ID", 255);
  k.receive_data_address = u("ReceiveDataAddress", 255);
  k.receive_data_size = u("ReceiveDataSize", 255);
  k.button_value = u("ButtonValue", 0xFFFF);
  k.pa1 = u("PA1", 255);
  k.pa2 = u("PA2", 255);
  k.pa3 = u("PA3", 255);
  k.pa4 = u("PA4", 255);
  k.checksum = u("CheckSum", 255);
  return k;
}

priority_entry read_priority(const xml_in& x, const pugi::xml_node& entry) {
  priority_entry e;
  const auto k = x.need(entry, "Key");
  e.key = k.child_value();
  e.key_type = xml_in::type_of(k);
  if (const auto v = value_of(x, entry, "PriorityMotion", true)) {
    priority_entry::motion m;
    m.name = x.text(v, "Name");
    m.port = x.text(v, "Port");
    m.compare = compare_of(x, v);
    m.value = static_cast<int>(x.integer(v, "Value", -65536, 65535));
    m.address = static_cast<long>(x.integer(v, "Address", -1, 0x3FFFF));
    e.value = m;
  }
  return e;
}

/** The DictionaryEntry children of @p n, each checked for its name. */
std::vector<pugi::xml_node> entries(const xml_in& x, const pugi::xml_node& n) {
  std::vector<pugi::xml_node> out;
  for (auto e = n.first_child(); e; e = e.next_sibling()) {
    if (std::string_view(e.name()) != "DictionaryEntry")
      x.fail(e, std::string("<") + n.name() + "> holds <DictionaryEntry> only");
    out.push_back(e);
  }
  return out;
}

constexpr const char* known_root[] = {"Config",
                                      "AdcReference",
                                      "Kri3",
                                      "MotionDataCollection",
                                      "ServoConfigParams",
                                      "StartupMotionAddress",
                                      "LowPowerMotionAddress",
                                      "LowPowerValue",
                                      "PriorityMotionCollection",
                                      "PictureFileName",
                                      "LinkFileList",
                                      "ConvertFileList",
                                      "ProjectTitle",
                                      "FileName",
                                      "Path",
                                      "Name",
                                      "Anchors",
                                      "SoundDeviceNumber"};

}  // namespace

project parse_project(std::string_view text, const std::string& source) {
  const xml_in x(text, source, "Rcb4", "a HeartToHeart4 project (.h4p)");
  const auto r = x.root();
  lines at;
  at.root = r;
  project p;
  const auto config = bytes_of(x, r, "Config", 2);
  p.config = static_cast<std::uint16_t>(config[0] | (config[1] << 8));
  const auto adc = bytes_of(x, r, "AdcReference", 22);
  for (std::size_t i = 0; i < 11; ++i)
    p.adc_reference[i] = static_cast<std::uint16_t>(adc[2 * i] | (adc[2 * i + 1] << 8));
  p.kri3 = read_kri3(x, x.need(r, "Kri3"));
  const auto motions = entries(x, x.need(r, "MotionDataCollection"));
  if (motions.size() != motion_count)
    x.fail(r.child("MotionDataCollection"), "has " + std::to_string(motions.size()) + " motions, not 120");
  for (std::size_t i = 0; i < motions.size(); ++i) p.motions.push_back(read_motion(x, motions[i], i, at));
  const auto servos = entries(x, x.need(r, "ServoConfigParams"));
  if (servos.size() != servo_count)
    x.fail(r.child("ServoConfigParams"), "has " + std::to_string(servos.size()) + " servos, not 35 (ICS 0..34)");
  for (const auto& s : servos) {
    at.servos.push_back(s);
    p.servos.push_back(read_servo(x, s));
  }
  at.startup = x.need(r, "StartupMotionAddress");
  p.startup_address = static_cast<long>(x.integer(r, "StartupMotionAddress", -1, 0x3FFFF));
  if (r.child("LowPowerMotionAddress"))
    p.low_power_address = static_cast<long>(x.integer(r, "LowPowerMotionAddress", -1, 0x3FFFF));
  if (r.child("LowPowerValue")) p.low_power_value = static_cast<long>(x.integer(r, "LowPowerValue", -65536, 65535));
  for (const auto& e : entries(x, x.need(r, "PriorityMotionCollection"))) {
    at.priority.push_back(e);
    p.priority.push_back(read_priority(x, e));
  }
  const auto str = [&](const char* name) { return std::string(r.child(name).child_value()); };
  p.picture_file = str("PictureFileName");
  p.link_files = str("LinkFileList");
  p.convert_files = str("ConvertFileList");
  p.title = str("ProjectTitle");
  p.file_name = str("FileName");
  p.path = str("Path");
  p.name = str("Name");
  if (const auto a = r.child("Anchors"); a.first_child() || a.first_attribute()) p.anchors_xml = xml_in::raw(a);
  if (r.child("SoundDeviceNumber")) p.sound_device = static_cast<long>(x.integer(r, "SoundDeviceNumber", -1, 255));
  for (auto c = r.first_child(); c; c = c.next_sibling()) {
    if (c.type() != pugi::node_element) continue;
    if (std::find_if(std::begin(known_root), std::end(known_root),
                     [&](const char* k) { return std::string_view(k) == c.name(); }) == std::end(known_root))
      p.other_xml.push_back(xml_in::raw(c));
  }
  check_project(p, [&](const place& pl) {
    const auto node = [&] {
      switch (pl.kind) {
        case place::in_motion: return at.motions[pl.index];
        case place::in_frame: return at.frames[pl.index][pl.frame];
        case place::in_servo: return at.servos[pl.index];
        case place::in_startup: return at.startup;
        case place::in_priority: return at.priority[pl.index];
        case place::in_root: break;
      }
      return at.root;
    }();
    return x.where(node) + (pl.kind == place::in_root || pl.kind == place::in_startup ? "" : " of " + describe(pl));
  });
  return p;
}

project load_project(const std::filesystem::path& path) {
  return parse_project(detail::read_file(path, "a HeartToHeart4 project"), path.string());
}

}  // namespace rcb4::robot::hth4
