// Tests' helper: the error a bad profile gets (its "FILE:LINE:COLUMN: what"), for the profile tests.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/robot/profile.hpp>

#include <catch2/catch.hpp>

#include <string>

namespace rcb4::test {

/** The profile_error parsing @p text as "bad.yaml" gives; a failed test when it parses. */
inline std::string profile_error_of(const std::string& text) {
  try {
    rcb4::robot::parse_profile(text, "bad.yaml");
  } catch (const rcb4::robot::profile_error& e) {
    return e.what();
  }
  FAIL("the profile was accepted:\n" << text);
  return {};
}

}  // namespace rcb4::test
