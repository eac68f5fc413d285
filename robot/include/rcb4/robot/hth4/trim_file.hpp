// rcb4 — HTH4 trim files (.h4t, hth4-files.md §6): a snapshot of every servo's trim, read and
// written (XML through pugixml).
// SPDX-License-Identifier: BSL-1.0
//
//   <ArrayOfDictionaryEntry xmlns:xsi=… xmlns:xsd=…>
//     <DictionaryEntry>
//       <Key xsi:type="xsd:string">left_knee</Key>
//       <Value xsi:type="PositionData"><Name>left_knee</Name><ID>8</ID><DeviceNumber>16</DeviceNumber>
//         <Trim>-40</Trim><Position>7500</Position></Value>
//     </DictionaryEntry>
//     … one per servo, in ICS order …
//   </ArrayOfDictionaryEntry>
//
// An import matches on DeviceNumber (the ICS number), not on the name (§6); the trim goes to the
// servo block's +2 in RAM and in its ROM image (§2.3), as `rcb4 trim set --persist` does.
#pragma once

#include <rcb4/robot/hth4/project.hpp>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rcb4::robot::hth4 {

/** One servo's entry of a trim file. */
struct trim_entry {
  std::string name;            ///< the key and Name
  unsigned id = 0;             ///< the servo ID on its port
  unsigned device_number = 0;  ///< the ICS number, 0..34
  int trim = 0;                ///< signed 16-bit
  int position = 7500;         ///< [U] (§11.6)
  friend bool operator==(const trim_entry&, const trim_entry&) = default;
};

/** Parses a trim file's @p text; @p source names it in errors. Each DeviceNumber once, 0..34. Throws profile_error. */
std::vector<trim_entry> parse_trim_file(std::string_view text, const std::string& source);
/** Reads and parses @p path. Throws profile_error. */
std::vector<trim_entry> load_trim_file(const std::filesystem::path& path);
/** The entries as HTH4 writes them. */
std::string trim_file_xml(const std::vector<trim_entry>& entries);
/** The trims of a project's 35 servos, as HTH4 saves them from its servo window. */
std::vector<trim_entry> trims_of(const project& p);

}  // namespace rcb4::robot::hth4
