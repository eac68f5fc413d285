#!/usr/bin/env python3
# The firmware-size bench: one job (ping, read the config word and 20 servo positions, move two
# servos with one CONST) built for a Cortex-M4 three ways, and the bytes of code each adds to an
# empty program, printed side by side (figures, never asserted; docs/performance.md has them):
#   job_codec    the codec's command types, as a firmware author writes from docs/codec.md
#   job_variant  the same, each command passed as the rcb4::command variant
#   job_ops      the documented operations path: the link, ops::read_config, the planner's reads
# Build: arm-none-eabi-g++ -std=c++20 -Os -mcpu=cortex-m4 -mthumb, no exceptions or RTTI, sections
# collected (--gc-sections), newlib-nano; each program with this folder's board support (uart.cpp).
#   firmware_size.py [arm-none-eabi-g++]
# Exit 0 when every program built; 77 (skipped) without the compiler; 1 when one did not build.
# SPDX-License-Identifier: BSL-1.0
import glob
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
INCLUDE = os.path.join(HERE, "..", "..", "..", "include")
CXX = sys.argv[1] if len(sys.argv) > 1 else shutil.which("arm-none-eabi-g++")
if not CXX:
    print("SKIPPED: arm-none-eabi-g++ is not installed (cmake/install-deps.sh installs gcc-arm-none-eabi)")
    sys.exit(77)
SIZE = CXX[: -len("g++")] + "size"
FLAGS = ["-std=c++20", "-Os", "-mcpu=cortex-m4", "-mthumb", "-fno-exceptions", "-fno-rtti", "-ffunction-sections",
         "-fdata-sections", "-fstack-usage", "-Wall", "-Wextra", "-Wpedantic", "-Wconversion", "-Werror"]
LINK = ["-Wl,--gc-sections", "--specs=nano.specs", "--specs=nosys.specs"]
PROGRAMS = [("empty", "an empty program (the baseline)"),
            ("job_codec", "the codec's command types"),
            ("job_variant", "each command as the rcb4::command variant"),
            ("job_ops", "the operations path (link, read_config, planned reads)")]

failed = False
rows = []
with tempfile.TemporaryDirectory() as tmp:
    for name, what in PROGRAMS:
        out = os.path.join(tmp, name)
        os.makedirs(out)
        elf = os.path.join(out, name + ".elf")
        p = subprocess.run([CXX, *FLAGS, "-I", INCLUDE, os.path.join(HERE, name + ".cpp"), os.path.join(HERE, "uart.cpp"),
                            *LINK, "-o", elf], cwd=out, capture_output=True, text=True)
        if p.returncode != 0:
            print(f"FAIL {name} did not build:\n{p.stderr[-3000:]}")
            failed = True
            continue
        text, data, bss = subprocess.run([SIZE, elf], capture_output=True, text=True).stdout.split("\n")[1].split()[:3]
        worst = (0, "")
        for su in glob.glob(os.path.join(out, "*.su")):
            for line in open(su):
                parts = line.rstrip("\n").split("\t")
                if len(parts) >= 2 and parts[1].isdigit() and int(parts[1]) > worst[0]:
                    worst = (int(parts[1]), parts[0].split(":")[-1])
        rows.append((name, what, int(text), int(data), int(bss), worst))

base = next((r[2] for r in rows if r[0] == "empty"), None)
print(f"{'program':<12} {'code':>7} {'beyond empty':>13} {'data':>5} {'bss':>5} {'largest frame':>13}  what")
for name, what, text, data, bss, (stack, fn) in rows:
    beyond = "" if base is None else f"{text - base:,}"
    print(f"{name:<12} {text:>7,} {beyond:>13} {data:>5} {bss:>5} {stack:>8} B     {what}" + (f" ({fn})" if fn else ""))
codec = next((r[2] for r in rows if r[0] == "job_codec"), None)
if base is not None and codec is not None:
    print(f"KONDO's Arduino library, the same job (issue 42's figure): 1,480 B beyond empty; "
          f"job_codec is {(codec - base) / 1480:.2f}x that")
sys.exit(1 if failed else 0)
