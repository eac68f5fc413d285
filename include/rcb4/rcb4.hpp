// rcb4 — the whole codec: include this one header.
// SPDX-License-Identifier: BSL-1.0
//
// Standard library only, constexpr, no heap, builds with -fno-exceptions -fno-rtti.
// See protocol.md (the project's specification) for the sections cited in the headers.
#pragma once

#include <rcb4/command.hpp>
#include <rcb4/error.hpp>
#include <rcb4/frame.hpp>
#include <rcb4/memory_map.hpp>
#include <rcb4/operand.hpp>
#include <rcb4/parse_result.hpp>
#include <rcb4/reply.hpp>
#include <rcb4/result.hpp>
#include <rcb4/servo_set.hpp>
#include <rcb4/values.hpp>
#include <rcb4/vector_entry.hpp>
