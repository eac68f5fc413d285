// Must not compile: 20000 is neither a 0–16383 position nor FREE/HOLD.
#include <rcb4/rcb4.hpp>
int main() {
  rcb4::single_servo s{0, 20000, 10};
  (void)s;
}
