// rcb4 — writing a project value as HTH4 writes a .h4p (hth4-files.md §2.1–§2.6, §10): the element
// order of §2.1, both namespaces, every xsi:type, all 120 motions and 35 servos, each used motion
// ending in `03 0D 10 FF`, CRLF and two-space indentation.
// SPDX-License-Identifier: BSL-1.0
#include "project_check.hpp"
#include "xml.hpp"

namespace rcb4::robot::hth4 {

namespace {

using detail::add;
using detail::add_entry;
using detail::add_raw;

void add_bytes(pugi::xml_node n, const char* name, std::span<const std::uint8_t> bytes) {
  auto e = n.append_child(name);
  for (const auto b : bytes) add(e, "unsignedByte", b);
}

void add_motion(pugi::xml_node coll, const motion_entry& m) {
  char key[8];
  std::snprintf(key, sizeof key, "M%03u", (m.number + 1) % 1000);
  auto v = add_entry(coll, key, "Motion");
  add(v, "Number", m.number);
  add(v, "Name", m.name);
  add(v, "Date", m.date);
  add(v, "ButtonData", m.buttons);
  add(v, "CompareType", compare_name(m.compare));
  auto data = v.append_child("MotionData");
  for (const auto& f : m.frames) {
    auto a = add(data, "anyType", frame_text(f));
    a.append_attribute("xsi:type") = "xsd:string";
  }
  add(v, "Address", m.address);
  add(v, "KeyCode", m.key_code);
}

void add_servo(pugi::xml_node coll, const servo_entry& s) {
  auto v = add_entry(coll, s.name, "ServoItem");
  add(v, "Name", s.name);
  add(v, "Count", s.count);
  add(v, "RomAddress", s.rom_address);
  add(v, "RamAddress", s.ram_address);
  add(v, "Mode", s.mode == servo_mode::normal ? "Normal" : "None");
  add(v, "Port", s.port == servo_port::sio2 ? "SIO2" : "SIO1");
  add(v, "DeviceNumber", s.device_number);
  add(v, "Code", s.code);
  add(v, "ID", s.id);
  add(v, "Trim", s.trim);
  add(v, "Position", s.position);
  add(v, "Mixing1Address", s.mixing1_address);
  add(v, "Mixing1Rate", s.mixing1_rate);
  add(v, "Mixing2Address", s.mixing2_address);
  add(v, "Mixing2Rate", s.mixing2_rate);
  add(v, "DisplayRate", s.display_rate);
  auto l = v.append_child("Location");
  add(l, "X", s.x);
  add(l, "Y", s.y);
  add_raw(v, s.group_xml);
  add_raw(v, s.fore_color_xml);
  add_raw(v, s.back_color_xml);
}

void add_kri3(pugi::xml_node r, const kri3_block& k) {
  auto n = r.append_child("Kri3");
  add(n, "Name", k.name);
  add(n, "Count", k.count);
  add(n, "RomAddress", k.rom_address);
  add(n, "RamAddress", k.ram_address);
  add(n, "DeviceNumber", k.device_number);
  add(n, "Code", k.code);
  add(n, "ID", k.id);
  add(n, "ReceiveDataAddress", k.receive_data_address);
  add(n, "ReceiveDataSize", k.receive_data_size);
  add(n, "ButtonValue", k.button_value);
  add(n, "PA1", k.pa1);
  add(n, "PA2", k.pa2);
  add(n, "PA3", k.pa3);
  add(n, "PA4", k.pa4);
  add(n, "CheckSum", k.checksum);
}

void add_priority(pugi::xml_node coll, const priority_entry& p) {
  auto v = add_entry(coll, p.key, p.value ? "PriorityMotion" : nullptr, p.key_type.c_str());
  if (!p.value) return;
  add(v, "Name", p.value->name);
  add(v, "Port", p.value->port);
  add(v, "CompareType", compare_name(p.value->compare));
  add(v, "Value", p.value->value);
  add(v, "Address", p.value->address);
}

}  // namespace

std::string project_xml(const project& p) {
  pugi::xml_document doc;
  auto r = detail::new_root(doc, "Rcb4");
  const std::uint8_t config[] = {static_cast<std::uint8_t>(p.config), static_cast<std::uint8_t>(p.config >> 8)};
  add_bytes(r, "Config", config);
  std::array<std::uint8_t, 22> adc{};
  for (std::size_t i = 0; i < 11; ++i) {
    adc[2 * i] = static_cast<std::uint8_t>(p.adc_reference[i]);
    adc[2 * i + 1] = static_cast<std::uint8_t>(p.adc_reference[i] >> 8);
  }
  add_bytes(r, "AdcReference", adc);
  add_kri3(r, p.kri3);
  auto motions = r.append_child("MotionDataCollection");
  for (const auto& m : p.motions) add_motion(motions, m);
  auto servos = r.append_child("ServoConfigParams");
  for (const auto& s : p.servos) add_servo(servos, s);
  add(r, "StartupMotionAddress", p.startup_address);
  add(r, "LowPowerMotionAddress", p.low_power_address);
  add(r, "LowPowerValue", p.low_power_value);
  auto prio = r.append_child("PriorityMotionCollection");
  for (const auto& e : p.priority) add_priority(prio, e);
  add(r, "PictureFileName", p.picture_file);
  add(r, "LinkFileList", p.link_files);
  add(r, "ConvertFileList", p.convert_files);
  add(r, "ProjectTitle", p.title);
  add(r, "FileName", p.file_name);
  add(r, "Path", p.path);
  add(r, "Name", p.name);
  if (p.anchors_xml.empty())
    r.append_child("Anchors");
  else
    add_raw(r, p.anchors_xml);
  add(r, "SoundDeviceNumber", p.sound_device);
  for (const auto& o : p.other_xml) add_raw(r, o);
  return detail::serialize(doc);
}

void save_project(const std::filesystem::path& path, const project& p) {
  check_project(p, path.string());
  detail::write_file(path, project_xml(p));
}

}  // namespace rcb4::robot::hth4
