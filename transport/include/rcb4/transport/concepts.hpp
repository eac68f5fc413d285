// rcb4 — what a byte stream must offer to carry RCB-4 frames.
// SPDX-License-Identifier: BSL-1.0
//
// Any Asio stream fits: serial_port, ip::tcp::socket, posix::stream_descriptor, a test stream.
#pragma once

#include <boost/asio/buffer.hpp>
#include <boost/system/error_code.hpp>

#include <concepts>
#include <cstddef>

namespace rcb4::transport {

namespace detail {
struct io_handler {
  void operator()(boost::system::error_code, std::size_t) const {}
};
}  // namespace detail

/**
 * What basic_client needs of a stream: an executor, async_read_some and async_write_some (one
 * buffer, any completion handler), and close(ec), which ends pending operations (the client
 * closes the line when it goes away).
 */
template <class S>
concept AsyncByteStream = requires(S& s, boost::asio::mutable_buffer mb, boost::asio::const_buffer cb,
                                   boost::system::error_code& ec) {
  typename S::executor_type;
  { s.get_executor() } -> std::convertible_to<typename S::executor_type>;
  s.async_read_some(mb, detail::io_handler{});
  s.async_write_some(cb, detail::io_handler{});
  s.close(ec);
};

/**
 * A stream with a POSIX descriptor (serial_port, tcp_socket, stream_descriptor): blocking calls
 * on an idle line then do their I/O on the calling thread (client_options::direct_io).
 */
template <class S>
concept DescriptorStream = AsyncByteStream<S> && requires(S& s) {
  { s.native_handle() } -> std::convertible_to<int>;
};

}  // namespace rcb4::transport
