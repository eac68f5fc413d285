// rcb4 — bytes that failed their parity check, as errors: the decoder of a marked serial line.
// SPDX-License-Identifier: BSL-1.0
//
// The RCB-4 and ICS lines are 8E1 (protocol.md §1, ics.md §1). With termios' INPCK alone, Linux
// hands a byte that failed its parity (or framing) check to the program as 0x00: a valid value
// (an ICS nibble, a RAM byte), and one that an ICS reply, which has no checksum, cannot reject.
// transport/serial.hpp therefore opens both lines with PARMRK (termios(3)), and the kernel marks instead:
//
//   wire byte                     what read() returns
//   X, not 0xFF, arrived intact   X
//   0xFF arrived intact           FF FF   (the escape: doubled)
//   X with a parity/framing error FF 00 X
//   a break                       FF 00 00
//
// line_marks turns that stream back into data bytes and counts the damaged ones. A mark may be
// split over two reads, so the decoder keeps its state from one call to the next: one decoder
// per line, kept as long as the descriptor. It needs nothing but the standard library (firmware,
// fuzzers, other transports can use it).
//
// Why marks and not IGNPAR (the kernel drops a damaged byte): a dropped byte shortens the reply,
// so the exchange can only fail at its deadline, and on a line without checksums (ICS) a byte of
// the next reply could slide into its place; a mark fails the exchange at once, at the byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace rcb4::link {

/** The decoder of a PARMRK-marked line (see the table above). Copyable, no allocation. */
class line_marks {
 public:
  /** What decode() found in one chunk. */
  struct decoded {
    std::size_t size = 0;           ///< data bytes now at the front of the chunk
    std::size_t damaged = 0;        ///< bytes that failed their parity or framing check, or breaks
    std::size_t first_damaged = 0;  ///< data bytes [0, first_damaged) arrived before the first damaged one
    std::size_t clean_from = 0;     ///< data bytes [clean_from, size) arrived after the last damaged one
  };

  /**
   * Decodes the raw bytes of @p chunk in place: its data bytes move to its front (there are never
   * more of them than raw bytes). A mark that the chunk ends inside is finished by the next call.
   */
  constexpr decoded decode(std::span<std::uint8_t> chunk) noexcept {
    decoded d;
    for (const std::uint8_t raw : chunk) {
      switch (state_) {
        case state::data:
          if (raw == 0xFF)
            state_ = state::escape;
          else
            chunk[d.size++] = raw;
          break;
        case state::escape:
          if (raw == 0xFF) {  // FF FF: an intact 0xFF
            chunk[d.size++] = 0xFF;
            state_ = state::data;
          } else if (raw == 0x00) {  // FF 00: a mark; the damaged byte follows
            state_ = state::mark;
          } else {  // FF X, a sequence the kernel never writes: the line is not marked as assumed
            if (d.damaged++ == 0) d.first_damaged = d.size;  // (another program changed its settings)
            d.clean_from = d.size;                           // nothing of it is data
            state_ = state::data;
          }
          break;
        case state::mark:  // FF 00 X: X (00 for a break) failed its check
          if (d.damaged++ == 0) d.first_damaged = d.size;
          d.clean_from = d.size;
          state_ = state::data;
          break;
      }
    }
    return d;
  }

  /** True when the last chunk ended inside a mark or an escape (more raw bytes finish it). */
  constexpr bool inside_mark() const noexcept { return state_ != state::data; }
  /** Forgets a mark begun on a descriptor that is gone (a new line starts clean). */
  constexpr void reset() noexcept { state_ = state::data; }

 private:
  enum class state : std::uint8_t { data, escape, mark };
  state state_ = state::data;
};

}  // namespace rcb4::link
