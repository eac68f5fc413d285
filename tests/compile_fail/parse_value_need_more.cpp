// Must not compile: the value of a reply still missing bytes (two of an ACK's four are in); the
// constant evaluation stops at the access, as a run-time one traps.
#include <array>
#include <rcb4/rcb4.hpp>
constexpr std::array<std::uint8_t, 2> half{0x04, 0x0F};
static_assert(rcb4::parse_reply(half, rcb4::reply_shape{0x0F, false, 0}).value().is_ack());
int main() {}
