// Must not compile: RAM ends at 0x048F.
#include <rcb4/rcb4.hpp>
int main() {
  constexpr rcb4::ram_address a{0x0490};
  (void)a;
}
