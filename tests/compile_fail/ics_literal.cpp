// Must not compile: ICS 36 does not exist (0–35).
#include <rcb4/rcb4.hpp>
int main() {
  rcb4::single_servo s{36, 7500, 10};
  (void)s;
}
