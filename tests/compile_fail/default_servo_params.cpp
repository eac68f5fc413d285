// Must not compile: a default-constructed SPEED/STRETCH would set ICS 0's stretch; make() only.
#include <rcb4/rcb4.hpp>
int main() {
  const rcb4::servo_params p{};
  return static_cast<int>(rcb4::wire_size(rcb4::command{p}));
}
