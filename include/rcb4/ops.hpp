// rcb4 — all operations (sans-I/O): identify and config, memory, servos and the read
// planner, motions, sensors, counters / parameters / timers / receiver emulation.
// SPDX-License-Identifier: BSL-1.0
#pragma once

#include <rcb4/ops/io.hpp>
#include <rcb4/ops/layout.hpp>
#include <rcb4/ops/memory.hpp>
#include <rcb4/ops/motion.hpp>
#include <rcb4/ops/operation.hpp>
#include <rcb4/ops/planner.hpp>
#include <rcb4/ops/sensors.hpp>
#include <rcb4/ops/servos.hpp>
#include <rcb4/ops/survey.hpp>
#include <rcb4/ops/system.hpp>
