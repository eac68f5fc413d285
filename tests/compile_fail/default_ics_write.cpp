// Must not compile: a default-constructed EEPROM write would rewrite servo 0 with a zeroed image.
#include <rcb4/ics/commands.hpp>
int main() {
  const rcb4::ics::write_eeprom w{};
  return static_cast<int>(w.request().size);
}
