// rcb4 — KONDO's USB adapters by their USB ids (ics.md §6): which line each carries, so that a
// port list and the udev rule (cmake/udev/60-rcb4.rules) know every one that reaches an RCB-4's
// COM port or an ICS servo. All are FTDI chips; only 165C:0002 is in Linux's ftdi_sio table, the
// others are bound to it by the udev rule.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rcb4::transport {

/** KONDO's USB vendor id. */
inline constexpr std::uint16_t kondo_vendor = 0x165C;

/** What an adapter's line reaches. */
enum class adapter_line : std::uint8_t {
  com,         ///< an RCB-4's COM port
  ics,         ///< ICS servos (one servo at a time for setup)
  com_or_ics,  ///< either, by its mode switch (the LED is red in ICS mode)
  not_servos,  ///< a KONDO device that reaches neither (a band monitor, an RS485 converter)
};

/** One of KONDO's USB products. */
struct kondo_adapter {
  std::uint16_t product;  ///< USB product id
  std::string_view name;  ///< KONDO's product name
  adapter_line line;      ///< what it carries
  std::string_view note;  ///< rates, catalogue number
};

/** Every KONDO USB id known (ics.md §6). */
inline constexpr std::array<kondo_adapter, 9> kondo_adapters{{
    {0x0001, "ICS USB ADAPTER", adapter_line::ics, "ICS at 115200 only (No. 01106)"},
    {0x0002, "SERIAL USB ADAPTER", adapter_line::com, "RCB-4 COM"},
    {0x0003, "ARC Type4", adapter_line::not_servos, "not for servos"},
    {0x0004, "2.4GHz USB Band Monitor", adapter_line::not_servos, "not for servos"},
    {0x0005, "SERIAL USB ADAPTER 2", adapter_line::com, "RCB-4 COM"},
    {0x0006, "ICS USB ADAPTER HS", adapter_line::ics, "ICS up to 1.25 Mbaud (No. 02042)"},
    {0x0007, "SERIAL USB ADAPTER HS", adapter_line::com, "RCB-4 COM"},
    {0x0008, "DUAL USB ADAPTER HS", adapter_line::com_or_ics, "RCB-4 COM or ICS by its switch (No. 02116)"},
    {0x0009, "RS485 USB/SERIAL CONVERTER", adapter_line::not_servos, "not for servos"},
}};

/** The KONDO product @p vendor:@p product is, if it is one. */
constexpr std::optional<kondo_adapter> find_kondo_adapter(std::uint16_t vendor, std::uint16_t product) noexcept {
  if (vendor != kondo_vendor) return std::nullopt;
  for (const auto& a : kondo_adapters)
    if (a.product == product) return a;
  return std::nullopt;
}

/** "RCB-4 COM", "ICS", "RCB-4 COM or ICS (mode switch)", "not for servos". */
constexpr std::string_view line_text(adapter_line l) noexcept {
  switch (l) {
    case adapter_line::com: return "RCB-4 COM";
    case adapter_line::ics: return "ICS";
    case adapter_line::com_or_ics: return "RCB-4 COM or ICS (mode switch)";
    case adapter_line::not_servos: return "not for servos";
  }
  return "?";
}

}  // namespace rcb4::transport
