#!/usr/bin/env bash
# Installs from Debian 12 whatever the project needs and is missing; does nothing when all is there.
# Usage: cmake/install-deps.sh            (needs root or sudo only when something is missing)
#        cmake/install-deps.sh --list     (prints the packages, one a line: tests/deps_test.py checks
#                                           that everything the suite runs comes from them)
# Only these packages and what they *depend* on are installed (--no-install-recommends): a program
# or module the suite uses that another package merely recommends must be listed here itself.
set -euo pipefail

packages=(
  g++ cmake ninja-build pkg-config    # toolchain
  clang-16 libclang-rt-16-dev          # clang with libFuzzer and sanitizers (clang 14 crashes on consteval)
  clang-format                         # formatting (.clang-format)
  catch2 libfmt-dev libbenchmark-dev   # tests, formatters, micro-benchmarks
  libboost1.81-dev                     # Boost.Asio for transport/ (1.74's Asio breaks under GCC 12 in C++20)
  libcli11-dev nlohmann-json3-dev      # the rcb4 tool's arguments and JSON
  libyaml-cpp-dev                      # robot profiles and pose files (rcb4::profile)
  libpugixml-dev                       # HeartToHeart4 projects, motion and trim files (rcb4::profile's hth4 readers)
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib  # the codec built for firmware
  qemu-system-arm                      # runs the example firmware (examples/firmware) in the suite
  python3                              # a client in another language for the virtual board tests
  python3-venv python3-setuptools      # python.pip_install: pip in a venv builds pyrcb4 with Debian's setuptools
  ser2net                              # TCP bridge used by the transport tests
  libftdi1-dev                         # rcb4/link/libftdi_device.hpp: an FTDI adapter through libusb, no tty (examples/ftdi_ping)
  doxygen                              # API documentation (the docs.doxygen test)
  chromium chromium-driver python3-selenium  # rcb4 ui's tests in a real (headless) browser
  eslint                               # the page's JavaScript linted in the suite (lint.studio_js)
  libjs-three                          # three.js r111 (with OrbitControls): rcb4 ui draws the robot in 3D (embedded at build time)
  liburdfdom-tools                     # check_urdf: the suite checks that `rcb4 urdf` parses
  pybind11-dev python3-dev python3-pytest python3-numpy python3-serial  # pyrcb4, its tests, its benchmark
  python3-rospy python3-rosmaster python3-rostopic python3-sensor-msgs python3-trajectory-msgs \
  python3-std-srvs python3-std-msgs python3-diagnostic-msgs python3-rosservice python3-rosnode python3-roslaunch \
  python3-actionlib python3-actionlib-msgs python3-genpy python3-genmsg \
  python3-dynamic-reconfigure  # rcb4_ros: ROS 1's Python side only (its C++ packages would remove libboost1.81-dev); genpy generates the messages Debian lacks; dynamic_reconfigure's Python server (kxr_controller's parameters)
)

if [ "${1:-}" = --list ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  if [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" != "install ok installed" ]; then
    # python3 may come from elsewhere (pyenv); a working interpreter is enough.
    if [ "$p" = python3 ] && command -v python3 >/dev/null 2>&1; then continue; fi
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "rcb4: installing missing packages: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo="sudo"
  else
    echo "rcb4: not root and no sudo; install these by hand: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
# An empty or stale package list finds nothing; refresh it once.
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
# ROS 1's C++ development packages conflict with Boost 1.81's: make sure nothing took it away.
if [ "$(dpkg-query -W -f='${Status}' libboost1.81-dev 2>/dev/null)" != "install ok installed" ]; then
  echo "rcb4: libboost1.81-dev is no longer installed (a ROS C++ package removes it); reinstall it" >&2
  exit 1
fi
