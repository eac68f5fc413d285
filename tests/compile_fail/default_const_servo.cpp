// Must not compile: a default-constructed CONST would move ICS 0; it comes from make() only.
#include <rcb4/rcb4.hpp>
int main() {
  const rcb4::const_servo c{};
  return static_cast<int>(rcb4::wire_size(rcb4::command{c}));
}
