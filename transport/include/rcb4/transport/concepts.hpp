// rcb4 — what a byte stream must offer to carry RCB-4 frames.
// SPDX-License-Identifier: BSL-1.0
//
// Any Asio stream fits: serial_port, ip::tcp::socket, posix::stream_descriptor, a test fake.
#pragma once

#include <boost/asio/buffer.hpp>
#include <boost/system/error_code.hpp>

#include <concepts>
#include <cstddef>

namespace rcb4::transport {

namespace detail {
struct read_handler {
  void operator()(boost::system::error_code, std::size_t) const {}
};
}  // namespace detail

/** An Asio asynchronous byte stream: an executor, async_read_some and async_write_some. */
template <class S>
concept AsyncByteStream = requires(S& s, boost::asio::mutable_buffer mb, boost::asio::const_buffer cb) {
  typename S::executor_type;
  { s.get_executor() } -> std::convertible_to<typename S::executor_type>;
  s.async_read_some(mb, detail::read_handler{});
  s.async_write_some(cb, detail::read_handler{});
};

/** A synchronous byte stream: read_some and write_some with an error_code. */
template <class S>
concept SyncByteStream = requires(S& s, boost::asio::mutable_buffer mb, boost::asio::const_buffer cb,
                                  boost::system::error_code& ec) {
  { s.read_some(mb, ec) } -> std::convertible_to<std::size_t>;
  { s.write_some(cb, ec) } -> std::convertible_to<std::size_t>;
};

}  // namespace rcb4::transport
