// rcb4 — HeartToHeart4 (HTH4) project files (.h4p) as a typed value, read and written
// (hth4-files.md §1–§4; XML through pugixml).
// SPDX-License-Identifier: BSL-1.0
//
// A project is .NET XmlSerializer output with the root <Rcb4> (hth4-files.md §2.1):
//
//   <Rcb4 xmlns:xsi=… xmlns:xsd=…>
//     <Config>2 × <unsignedByte>, low first</Config>          config word (ROM 0x05DC)
//     <AdcReference>22 × <unsignedByte></AdcReference>        AD0..AD10, low first (ROM 0x08F6)
//     <Kri3>15 children</Kri3>                                the receiver block (§2.4)
//     <MotionDataCollection>120 × DictionaryEntry M001..M120, Value xsi:type="Motion" (§2.2)
//     <ServoConfigParams>35 × DictionaryEntry, key = servo name, Value xsi:type="ServoItem" (§2.3)
//     <StartupMotionAddress/> <LowPowerMotionAddress/> <LowPowerValue/>
//     <PriorityMotionCollection>13 (2.2 beta) or 14 (2.4.0) entries (§2.5)
//     <PictureFileName/> <LinkFileList/> <ConvertFileList/> <ProjectTitle/> <FileName/> <Path/>
//     <Name/> <Anchors/> <SoundDeviceNumber/>
//   </Rcb4>
//
// read_project() checks what a board would run before anything is written anywhere: every frame's
// SIZE byte and SUM (protocol.md §2), the `03 0D 10 FF` tail of every motion (§2.2), one slot base
// for all 120 motions and a layout the board knows (§4), no motion longer than its 2048-byte slot,
// every JUMP/CALL target inside the motion area, on a frame of its own slot or on the first byte
// of a used slot (§4 "Where targets point"), servos in ICS order with DeviceNumber = 2 × ID +
// (SIO2), known Mode/Port/CompareType names. An error names the file, the element and its line.
// write_project() writes the same schema (element order, both namespaces, every xsi:type, CRLF,
// two-space indentation; §1, §10); a written project reads back to the same value.
#pragma once

#include <rcb4/memory_map.hpp>
#include <rcb4/robot/profile.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rcb4::robot::hth4 {

/** Largest project, motion or trim file read (a real project is well under 2 MB). */
inline constexpr std::size_t max_file_bytes = 16u << 20;
/** Slots and servo entries of a 2.x project (§2.1). */
inline constexpr std::size_t motion_count = 120, servo_count = 35;

/** Rcb4.dll's CalcResultTypes (§2.2), in its order. */
enum class compare_type { equals, not_equals, greater_than, less_than, at_least, at_most, zero, none };
/** The name HTH4 writes ("Equals", "LessThanOrEqualTo", ...). */
std::string_view compare_name(compare_type c);

/** A servo entry's Mode (§2.3): allocated (Normal) or not (None). */
enum class servo_mode { normal, none };
/** A servo entry's Port (§2.3): SIO1 = connectors 1–4, SIO2 = 5–8. */
enum class servo_port { sio1, sio2 };

/** One slot of MotionDataCollection (§2.2). */
struct motion_entry {
  unsigned number = 0;        ///< 0-based slot index (M001 is 0)
  std::string name;           ///< HTH4 names an unused slot after its key ("M002")
  std::string date;           ///< ISO 8601 as written
  std::uint16_t buttons = 0;  ///< KRR button word (protocol.md §6); 0 = none
  compare_type compare = compare_type::equals;
  /** The compiled frames, JUMP/CALL targets absolute; the last is `03 0D 10 FF`. Empty: unused. */
  std::vector<std::vector<std::uint8_t>> frames;
  std::uint32_t address = 0;      ///< the slot's ROM address
  std::string key_code = "None";  ///< a PC keyboard shortcut (GUI only)
  /** The frames as one run of bytes, as they lie in the slot (the final FF included). */
  std::vector<std::uint8_t> code() const;
  friend bool operator==(const motion_entry&, const motion_entry&) = default;
};

/** One entry of ServoConfigParams (§2.3): a 20-byte servo block and how HTH4 shows it. */
struct servo_entry {
  std::string name;               ///< the dictionary key and Name
  unsigned count = 20;            ///< block size
  std::uint32_t rom_address = 0;  ///< the block's image, 0x0626 + 20k
  std::uint32_t ram_address = 0;  ///< the block, 0x0090 + 20k
  servo_mode mode = servo_mode::none;
  servo_port port = servo_port::sio1;
  unsigned device_number = 0;                                        ///< ICS number k = 2 × ID + (1 on SIO2)
  unsigned code = 0;                                                 ///< block byte +0 (0 = servo)
  unsigned id = 0;                                                   ///< servo ID on its port
  int trim = 0;                                                      ///< block +2..+3, signed
  int position = 7500;                                               ///< [U] (hth4-files.md §11.6)
  std::uint16_t mixing1_address = 0xFFFF, mixing2_address = 0xFFFF;  ///< 0xFFFF = none
  int mixing1_rate = 0, mixing2_rate = 0;
  std::string display_rate = "1";                         ///< GUI: a .NET double as written
  int x = 0, y = 0;                                       ///< GUI: Location
  std::string group_xml, fore_color_xml, back_color_xml;  ///< GUI: the elements as written
  friend bool operator==(const servo_entry&, const servo_entry&) = default;
};

/** The receiver block (§2.4): 11 bytes at RAM 0x034C. */
struct kri3_block {
  std::string name = "KRI-3";
  unsigned count = 11, rom_address = 0, ram_address = 844, device_number = 35;
  unsigned code = 1, id = 31, receive_data_address = 0, receive_data_size = 7;
  unsigned button_value = 0, pa1 = 0, pa2 = 0, pa3 = 0, pa4 = 0, checksum = 0;
  friend bool operator==(const kri3_block&, const kri3_block&) = default;
};

/** One entry of PriorityMotionCollection (§2.5); the motion is absent for a key-only entry. */
struct priority_entry {
  std::string key;                   ///< "0".."12", "-1" in 2.4.0
  std::string key_type = "xsd:int";  ///< the key's xsi:type as written
  struct motion {
    std::string name, port = "Battery";
    compare_type compare = compare_type::at_most;
    int value = 0;
    long address = -1;  ///< -1 = none
    friend bool operator==(const motion&, const motion&) = default;
  };
  std::optional<motion> value;
  friend bool operator==(const priority_entry&, const priority_entry&) = default;
};

/** A whole project. */
struct project {
  std::uint16_t config = 0;                       ///< the config word (protocol.md §6)
  std::array<std::uint16_t, 11> adc_reference{};  ///< AD0..AD10
  kri3_block kri3;
  std::vector<motion_entry> motions;  ///< 120, by number
  std::vector<servo_entry> servos;    ///< 35, ICS 0..34
  long startup_address = -1;          ///< the start-up motion's ROM address, -1 = none
  long low_power_address = -1, low_power_value = 0;
  std::vector<priority_entry> priority;  ///< 13 (2.2 beta) or 14 (2.4.0)
  std::string picture_file, link_files, convert_files, title, file_name, path, name;
  std::string anchors_xml;  ///< <Anchors> as written ([U])
  long sound_device = -1;
  /** Root elements this reader does not know, as written; written back after the known ones. */
  std::vector<std::string> other_xml;

  /** The layout the slots were compiled for: HTH4 2.0–2.1 (0x0BB8) or 2.2+ (0x0B80) (§4). */
  const rom_layout& layout() const;
  /** The entry of ICS number @p ics, or null. */
  const servo_entry* servo(unsigned ics) const;
  friend bool operator==(const project&, const project&) = default;
};

/** An empty project for @p layout: 120 unused slots, 35 unallocated servos, 14 priority keys. */
project empty_project(const rom_layout& layout = hth4_2_2);

/** Parses a project's @p text; @p source names it in errors ("FILE:LINE: element: what"). Throws profile_error. */
project parse_project(std::string_view text, const std::string& source);
/** Reads and parses @p path (at most max_file_bytes). Throws profile_error. */
project load_project(const std::filesystem::path& path);
/** The project as HTH4 writes it. */
std::string project_xml(const project& p);
/** Writes project_xml() to @p path. Throws profile_error when it cannot. */
void save_project(const std::filesystem::path& path, const project& p);

/** Checks a project value as parse_project() checks a file (what a writer or an importer built). Throws profile_error.
 */
void check_project(const project& p, const std::string& source);

/** Parses one frame as HTH4 writes it: upper-case hex pairs separated by single spaces. Nothing when it is not. */
std::optional<std::vector<std::uint8_t>> parse_frame_text(std::string_view text);
/** "08 00 02 57 04 00 02 67" */
std::string frame_text(std::span<const std::uint8_t> bytes);

/**
 * The frames of @p m moved from the layout at @p from_base to the one at @p to_base (§4
 * "Relocation"): every JUMP/CALL target in the motion area keeps its slot and offset, its SUM made
 * again. Targets are checked on reading, so none lies outside the area.
 */
std::vector<std::vector<std::uint8_t>> relocate(const std::vector<std::vector<std::uint8_t>>& frames,
                                                std::uint32_t from_base, std::uint32_t to_base);

}  // namespace rcb4::robot::hth4
