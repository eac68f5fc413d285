// Must not compile: a position is a whole number; 7999.99 would silently become 7999.
#include <rcb4/rcb4.hpp>
int main() {
  rcb4::servo_position p = 7999.99;
  (void)p;
}
