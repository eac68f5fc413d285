// rcb4 — what a client sends (request) and hands back (response, owning its bytes).
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/link/requests.hpp>
#include <rcb4/rcb4.hpp>

#include <variant>

namespace rcb4::transport {

/** A reply that owns its bytes (what the client hands back). */
struct response {
  reply_kind kind = reply_kind::ack;   ///< ACK, NACK or data
  std::uint8_t command = 0;            ///< the echoed CMD byte
  byte_buffer<max_reply_data> data{};  ///< data bytes (data replies; empty for ACK and NACK)
  /** A copy of @p r's content. */
  static response from(const reply& r) noexcept {
    response out;
    out.kind = r.kind();
    out.command = r.command();
    out.data = byte_buffer<max_reply_data>(r.bytes());
    return out;
  }
  /** A view as a codec reply (valid while this response lives). */
  reply view() const noexcept {
    switch (kind) {
      case reply_kind::ack: return reply::ack(command);
      case reply_kind::nack: return reply::nack(command);
      case reply_kind::data: break;
    }
    return reply::data(command, data.bytes()).value();
  }
  /** Little-endian word at @p offset of the data (the caller checks kind and size first). */
  std::uint16_t u16(std::size_t offset = 0) const noexcept {
    return static_cast<std::uint16_t>(data[offset] | (data[offset + 1] << 8));
  }
};

/** True for commands that can be repeated without changing the board: ping, VERSION, MOV → COM (the link's rule). */
inline bool is_idempotent(const command& c) noexcept { return link::is_idempotent(c); }

/** A command ready for the line: its frame, the shape of its reply, whether it may be repeated. */
struct request {
  request_frame frame;
  reply_shape shape;
  bool idempotent = false;
  /** The request for @p c. */
  static request of(const command& c) noexcept { return request{encode(c), expected_reply(c), is_idempotent(c)}; }
};

}  // namespace rcb4::transport
