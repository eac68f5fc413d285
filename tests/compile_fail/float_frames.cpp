// Must not compile: frames are a whole number; 2.5 would silently become 2.
#include <rcb4/rcb4.hpp>
int main() {
  rcb4::frames f = 2.5;
  (void)f;
}
