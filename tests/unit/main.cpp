// The one translation unit with Catch2's main (it takes a while to compile; keep it alone).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
