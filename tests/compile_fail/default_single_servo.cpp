// Must not compile: a default-constructed SINGLE would move ICS 0; every field is the caller's.
#include <rcb4/rcb4.hpp>
int main() {
  const rcb4::single_servo s;
  return static_cast<int>(rcb4::wire_size(rcb4::command{s}));
}
