// Must not compile: a constexpr MOV that reads past the end of RAM.
#include <rcb4/rcb4.hpp>
int main() {
  constexpr auto m = rcb4::move::read_ram(0x0480, 32).value();
  (void)m;
}
