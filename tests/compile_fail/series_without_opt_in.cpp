// Must not compile: SERIES (0x11) needs rcb4::series_opt_in (protocol.md §11.2).
#include <rcb4/rcb4.hpp>
int main() {
  auto s = rcb4::series_servo::make({{2, {7500, 30}}});
  (void)s;
}
