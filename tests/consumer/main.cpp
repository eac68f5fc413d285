// Uses the installed package: codec, formatters and the transport headers.
#include <rcb4/fmt.hpp>
#include <rcb4/rcb4.hpp>
#include <rcb4/transport/client.hpp>

#include <fmt/core.h>

int main() {
  const auto frame = rcb4::encode(rcb4::single_servo{0, 7500, 10});
  fmt::print("{}\n", rcb4::hex(frame.bytes()));
  return frame.size() == 7 ? 0 : 1;
}
