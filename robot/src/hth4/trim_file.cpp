// rcb4 — HTH4 trim files (.h4t, hth4-files.md §6).
// SPDX-License-Identifier: BSL-1.0
#include "xml.hpp"

#include <rcb4/robot/hth4/trim_file.hpp>

#include <set>

namespace rcb4::robot::hth4 {

std::vector<trim_entry> parse_trim_file(std::string_view text, const std::string& source) {
  const detail::xml_in x(text, source, "ArrayOfDictionaryEntry", "a HeartToHeart4 trim file (.h4t)");
  std::vector<trim_entry> out;
  std::set<unsigned> seen;
  for (auto e = x.root().first_child(); e; e = e.next_sibling()) {
    if (std::string_view(e.name()) != "DictionaryEntry")
      x.fail(e, "<ArrayOfDictionaryEntry> holds <DictionaryEntry> only");
    const auto v = x.need(e, "Value");
    x.need_type(v, "PositionData");
    trim_entry t;
    t.name = x.text(v, "Name");
    t.id = static_cast<unsigned>(x.integer(v, "ID", 0, 31));
    t.device_number = static_cast<unsigned>(x.integer(v, "DeviceNumber", 0, servo_count - 1));
    t.trim = static_cast<int>(x.integer(v, "Trim", -32768, 32767));
    t.position = static_cast<int>(x.integer(v, "Position", 0, 65535));
    if (!seen.insert(t.device_number).second)
      x.fail(x.need(v, "DeviceNumber"), "ICS " + std::to_string(t.device_number) + " has a second entry");
    out.push_back(std::move(t));
  }
  if (out.empty()) x.fail(x.root(), "has no entries");
  return out;
}

std::vector<trim_entry> load_trim_file(const std::filesystem::path& path) {
  return parse_trim_file(detail::read_file(path, "a HeartToHeart4 trim file"), path.string());
}

std::string trim_file_xml(const std::vector<trim_entry>& entries) {
  pugi::xml_document doc;
  auto r = detail::new_root(doc, "ArrayOfDictionaryEntry");
  for (const auto& t : entries) {
    auto v = detail::add_entry(r, t.name, "PositionData");
    detail::add(v, "Name", t.name);
    detail::add(v, "ID", t.id);
    detail::add(v, "DeviceNumber", t.device_number);
    detail::add(v, "Trim", t.trim);
    detail::add(v, "Position", t.position);
  }
  return detail::serialize(doc);
}

std::vector<trim_entry> trims_of(const project& p) {
  std::vector<trim_entry> out;
  for (const auto& s : p.servos) out.push_back({s.name, s.id, s.device_number, s.trim, s.position});
  return out;
}

}  // namespace rcb4::robot::hth4
