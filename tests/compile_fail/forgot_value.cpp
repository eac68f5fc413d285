// Must not compile: encode() of make()'s result, its .value() forgotten; the error says so.
#include <rcb4/rcb4.hpp>
int main() {
  const auto f = rcb4::encode(rcb4::move::read_ram(rcb4::ram::config, 2));
  (void)f;
}
