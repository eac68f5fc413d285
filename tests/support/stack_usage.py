#!/usr/bin/env python3
# The worst-case stack of the example firmware, from GCC's call graph with stack usage
# (-fcallgraph-info=su: one .ci file per source, VCG text): the deepest path from the reset
# handler, plus the interrupts that may come on top of it (each with the Cortex-M4's 32-byte
# exception frame; no FPU context: the image is built soft-float). Prints the figure and the path.
#   stack_usage.py FILE.ci...            (exit 1 when a path is unbounded: recursion, a dynamic frame)
# Library functions outside the image's sources (newlib-nano's memcpy/memset/memmove, libgcc's
# helpers) have no .ci of their own: each is counted at LIBRARY_BYTES, a leaf's frame. Indirect
# calls are bounded by the image's function-pointer targets: std::visit's dispatch functions and
# static constructors; the report names how many it bounded so.
# SPDX-License-Identifier: BSL-1.0
import re
import sys

LIBRARY_BYTES = 32   # newlib-nano's string functions and libgcc's helpers are leaves of a few words
EXCEPTION_FRAME = 32  # r0-r3, r12, lr, pc, xPSR pushed by the Cortex-M4 on entry (no FP context)
HANDLERS = ("systick_handler", "fault_handler")  # what may interrupt the main path, nested once each

node_re = re.compile(r'^node: \{ title: "([^"]*)" label: "((?:[^"\\]|\\.)*)"')
edge_re = re.compile(r'^edge: \{ sourcename: "([^"]*)" targetname: "([^"]*)"')
bytes_re = re.compile(r'(\d+) bytes \(([a-z,]+)\)')


def short(title):
    """A node's name without the source file it was compiled in."""
    return title.rsplit(":", 1)[-1] if "/" in title else title


def load(files):
    frames, labels, calls = {}, {}, {}
    for f in files:
        for line in open(f):
            m = node_re.match(line)
            if m:
                name, label = short(m.group(1)), m.group(2)
                b = bytes_re.search(label)
                if b:
                    frames[name] = (int(b.group(1)), b.group(2))
                labels.setdefault(name, label.split("\\n")[0])
                continue
            m = edge_re.match(line)
            if m:
                calls.setdefault(short(m.group(1)), set()).add(short(m.group(2)))
    return frames, labels, calls


def analyse(files):
    frames, labels, calls = load(files)
    problems = []
    indirect = sorted(n for n in frames if "__visit_invoke" in labels.get(n, "") or "__visit_invoke" in n
                      or n.startswith("_GLOBAL__sub_I"))
    bounded_indirect = []
    memo = {}

    def worst(name, stack):
        if name in stack:
            problems.append("recursion: " + " -> ".join(labels.get(n, n)[:60] for n in stack[stack.index(name):]))
            return 0, [name]
        if name in memo:
            return memo[name]
        if name == "__indirect_call":
            bounded_indirect.append(stack[-1])
            best = max((worst(t, stack + [name]) for t in indirect), default=(0, []), key=lambda x: x[0])
            memo[name] = (best[0], [name] + best[1])
            return memo[name]
        if name not in frames:
            memo[name] = (LIBRARY_BYTES, [name + " (library)"])
            return memo[name]
        own, kind = frames[name]
        if kind != "static" and kind != "dynamic,bounded":
            problems.append(f"{labels.get(name, name)}: a {kind} frame (alloca or a variable-length array)")
        below = max((worst(t, stack + [name]) for t in calls.get(name, ())), default=(0, []), key=lambda x: x[0])
        memo[name] = (own + below[0], [f"{labels.get(name, name)[:80]} ({own})"] + below[1])
        return memo[name]

    main_bytes, main_path = worst("reset_handler", [])
    total = main_bytes
    handlers = []
    for h in HANDLERS:
        if h in frames:
            b, _ = worst(h, [])
            handlers.append((h, b))
            total += EXCEPTION_FRAME + b
    return total, main_bytes, main_path, handlers, problems, len(set(bounded_indirect))


def main(argv):
    total, main_bytes, path, handlers, problems, indirect = analyse(argv[1:])
    print(f"worst stack: {total} bytes = {main_bytes} (reset_handler's deepest path)"
          + "".join(f" + {EXCEPTION_FRAME} + {b} ({h})" for h, b in handlers))
    print(f"  {indirect} function(s) call through a pointer: bounded by std::visit's dispatch functions")
    for step in path:
        print("  " + step)
    for p in problems:
        print("unbounded: " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
