// Must not compile: a run-time int must go through ics_number::make().
#include <rcb4/rcb4.hpp>
int main(int argc, char**) {
  rcb4::ics_number n{argc};
  (void)n;
}
