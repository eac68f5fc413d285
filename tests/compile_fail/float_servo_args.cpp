// Must not compile: a double where a command takes a position (Clang accepted 7500.0 as 7500).
#include <rcb4/rcb4.hpp>
int main() {
  rcb4::single_servo s{3, 7500.0, 10};
  (void)s;
}
