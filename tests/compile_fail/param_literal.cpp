// Must not compile: speed/stretch values are 1–127.
#include <rcb4/rcb4.hpp>
int main() {
  rcb4::servo_param p{128};
  (void)p;
}
