#!/usr/bin/env python3
# The documentation and the tool in step: README.md stays an entry point, every relative link in
# README.md and docs/*.md leads somewhere, every documented `rcb4 ...` command line uses words the
# tool has (asked through --help only: nothing here talks to a board), and every command the tool
# lists is documented in docs/tool.md.
#   /usr/bin/python3 tests/integration/docs_test.py RCB4_BINARY REPO_ROOT
# SPDX-License-Identifier: BSL-1.0
import collections
import glob
import os
import re
import shlex
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish  # noqa: E402

RCB4 = os.path.abspath(sys.argv[1])
ROOT = os.path.abspath(sys.argv[2])
README = os.path.join(ROOT, "README.md")
DOCS = sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
FILES = [README] + DOCS
README_MAX_LINES = 400
SHELL_LANGUAGES = {"", "sh", "bash", "shell", "console"}


def rel(path):
    return os.path.relpath(path, ROOT)


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read().split("\n")


# --- markdown: fenced blocks, prose, headings, links -----------------------------------------------

FENCE = re.compile(r"^\s*(```+|~~~+)\s*([\w+-]*)")


def split_markdown(lines):
    """Yields ("code", language, line number, text) for lines inside fenced blocks and ("prose",
    None, line number, text) for the others (fence lines themselves are neither)."""
    fence = None
    language = None
    for n, line in enumerate(lines, 1):
        m = FENCE.match(line)
        if fence is None and m:
            fence, language = m.group(1), m.group(2).lower()
            continue
        if fence is not None and line.strip().startswith(fence[:3]) and line.strip().strip(fence[0]) == "":
            fence = None
            continue
        yield ("code", language, n, line) if fence is not None else ("prose", None, n, line)


def strip_inline_code(text):
    return re.sub(r"`[^`]*`", "", text)


def github_slug(heading):
    """The anchor GitHub gives a heading: lower case, punctuation dropped (word characters, spaces
    and hyphens stay), spaces to hyphens."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip())  # a link: its text
    text = re.sub(r"[^\w\- ]", "", text.lower())
    return text.replace(" ", "-")


def anchors_of(path, cache={}):
    if path not in cache:
        seen = collections.Counter()
        anchors = set()
        for kind, _, _, line in split_markdown(read(path)):
            m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line) if kind == "prose" else None
            if m:
                slug = github_slug(m.group(2))
                anchors.add(slug if seen[slug] == 0 else f"{slug}-{seen[slug]}")
                seen[slug] += 1
        cache[path] = anchors
    return cache[path]


LINK = re.compile(r"\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")

# --- 1. README is an entry point; relative links resolve ------------------------------------------

readme_lines = read(README)
count = len(readme_lines) - (1 if readme_lines and readme_lines[-1] == "" else 0)
check(count < README_MAX_LINES, f"README.md has {count} lines (under {README_MAX_LINES})")

links_checked = 0
for path in FILES:
    for kind, _, n, line in split_markdown(read(path)):
        if kind != "prose":
            continue
        for target in LINK.findall(strip_inline_code(line)):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):  # http:, https:, mailto:
                continue
            where, _, anchor = target.partition("#")
            if path == README and not where:
                # Doxygen reads README.md as its main page (cmake/Doxyfile.in): it takes a link
                # within the page for a \ref to a symbol, and warns.
                check(False, f"README.md:{n}: link {target} within the page (Doxygen cannot resolve it)")
                continue
            dest = os.path.normpath(os.path.join(os.path.dirname(path), where)) if where else path
            links_checked += 1
            if where:
                check(os.path.exists(dest), f"{rel(path)}:{n}: link {target} -> {rel(dest)} exists")
            if anchor and os.path.isfile(dest) and dest.endswith(".md"):
                check(anchor in anchors_of(dest),
                      f"{rel(path)}:{n}: link {target}: #{anchor} is a heading of {rel(dest)}")
            if path == README and where.endswith(".md"):
                # Doxygen reads README.md as its main page (cmake/Doxyfile.in) and warns about a
                # bare link to a .md file outside its INPUT; one with an #anchor is a plain link.
                check(anchor != "", f"README.md:{n}: link {target} carries an #anchor (Doxygen)")
check(links_checked > 20, f"{links_checked} relative links checked")

stale = []
for path in FILES:
    for n, line in enumerate(read(path), 1):
        if re.search(r"examples/rcb4(?![\w-])", line):
            stale.append(f"{rel(path)}:{n}")
check(not stale, "no stale examples/rcb4 path (the tool is build/<preset>/bin/rcb4)"
      + (": " + ", ".join(stale) if stale else ""))

# --- the tool's help, parsed -------------------------------------------------------------------------

Help = collections.namedtuple("Help", "ok text options subcommands positionals")
help_cache = {}


def tool_help(path):
    """`rcb4 PATH... --help`, parsed: options (name -> takes a value), subcommands, whether the
    command takes positional arguments."""
    path = tuple(path)
    if path in help_cache:
        return help_cache[path]
    p = subprocess.run([RCB4, *path, "--help"], capture_output=True, text=True, timeout=30)
    options, subcommands, positionals = {}, [], False
    section = None
    for line in p.stdout.split("\n"):
        if re.match(r"^\S.*:$", line):
            section = line[:-1]
            continue
        if not line.strip():
            section = None if section != "Options" else section
            continue
        if section == "Options":
            m = re.match(r"^\s{1,4}(-[^\s]+)(.*)$", line)
            if m:
                # "--name TYPE[ Excludes: ...]" then 2+ spaces and the description (or a new line)
                spec = re.match(r"^(?: (\S.*?))?(?:\s{2,}|$)", m.group(2)).group(1) or ""
                takes_value = bool(spec) and not spec.startswith(("Excludes:", "Needs:"))
                for name in m.group(1).split(","):
                    options[name] = takes_value
        elif section == "Subcommands":
            m = re.match(r"^\s{1,4}([a-z][\w-]*)(\s|$)", line)
            if m:
                subcommands.append(m.group(1))
        elif section == "Positionals":
            positionals = True
    h = Help(p.returncode == 0, p.stdout, options, subcommands, positionals)
    help_cache[path] = h
    return h


top = tool_help([])
check(top.ok and "--device" in top.options and top.subcommands,
      f"rcb4 --help: {len(top.options)} global options, {len(top.subcommands)} commands")

# --- 2. every documented rcb4 command line uses the tool's words ---------------------------------------

PLACEHOLDER_SYNTAX = re.compile(r"…|\.\.\.|^\[|\]$|^<.*>$|\|")
SEPARATORS = {"|", "||", "&&", ";", "&"}
REDIRECT = re.compile(r"^\d*(>>|>&|<&|&>|>|<)(.*)$")


def segments(command):
    """The simple commands of a shell line: words, redirections dropped, split at | && || ;."""
    try:
        lexer = shlex.shlex(command, posix=True)
        lexer.whitespace_split = True
        lexer.commenters = ""
        words = list(lexer)
    except ValueError:
        words = command.split()
    segment, skip = [], False
    for w in words:
        if skip:
            skip = False
            continue
        if w in SEPARATORS:
            yield segment
            segment = []
            continue
        m = REDIRECT.match(w)
        if m:
            skip = m.group(2) == ""
            continue
        segment.append(w)
    yield segment


def is_rcb4(word):
    return word == "rcb4" or word.endswith("/rcb4")


def examine(words, strict):
    """Walks the words after `rcb4` as the tool would: global options, then subcommands as deep as
    --help lists them, then the command's own options and arguments. Returns (problems, skip
    reason or None, the command path)."""
    problems, path, seen = [], [], []  # seen: (option, the path it was given at)
    node, descending, i = top, True, 0
    while i < len(words):
        w = words[i]
        i += 1
        if w == "--":
            break
        if w.startswith("-") and w != "-":
            name = w.split("=", 1)[0]
            seen.append((name, tuple(path)))
            chain = [tool_help(path[:k]) for k in range(len(path), -1, -1)]
            takes = next((h.options[name] for h in chain if name in h.options), False)
            if takes and "=" not in w:
                i += 1
            continue
        if descending and w in node.subcommands:
            path.append(w)
            node = tool_help(path)
            if not node.ok:
                problems.append(f"`rcb4 {' '.join(path)} --help` fails")
                break
            continue
        if descending and node.subcommands and not node.positionals:
            if re.fullmatch(r"[A-Z][A-Z_]*", w):
                return problems, f"placeholder {w} where a command goes", path
            where = f"rcb4 {' '.join(path)}" if path else "rcb4"
            problems.append(f"{where} has no command '{w}' (its commands: {', '.join(node.subcommands)})")
            break
        if not node.positionals:
            problems.append(f"rcb4 {' '.join(path)} takes no argument '{w}'")
        descending = False
    else:
        if strict and node.subcommands and not path and not {"--version", "--help", "-h"} & {n for n, _ in seen}:
            problems.append("no command")
    for name, at in seen:
        if name in ("-h", "--help"):
            continue
        if not at:
            if name not in top.options:
                problems.append(f"{name} is not a global option of rcb4")
            continue
        own = any(name in tool_help(at[:k]).options for k in range(1, len(at) + 1))
        own = own or any(name in tool_help(path[:k]).options for k in range(1, len(path) + 1))
        if own:
            continue
        if name in top.options:
            if strict:
                problems.append(f"{name} is a global option, given after the command (the tool "
                                f"takes global options before it only)")
            continue
        problems.append(f"{name} is not an option of rcb4 {' '.join(path)} (nor a global one)")
    return problems, None, path


def documented_commands(path):
    """(line number, command line) for every rcb4 command in the file's shell blocks."""
    pending, start = "", None
    for kind, language, n, line in split_markdown(read(path)):
        if kind != "code" or language not in SHELL_LANGUAGES:
            continue
        text = line.strip()
        if pending:
            text = pending + " " + text
        else:
            start = n
        if text.endswith("\\"):
            pending = text[:-1].rstrip()
            continue
        pending = ""
        if text.startswith("$ "):
            text = text[2:]
        if " #" in text:
            text = text[: text.index(" #")]
        if not text or text.startswith("#"):
            continue
        for segment in segments(text):
            while segment and re.fullmatch(r"[A-Za-z_]\w*=\S*", segment[0]):  # VAR=value cmd
                segment = segment[1:]
            if segment and is_rcb4(segment[0]):
                yield start, " ".join(segment)


def inline_commands(path):
    for kind, _, n, line in split_markdown(read(path)):
        if kind == "prose":
            for span in re.findall(r"`([^`]+)`", line):
                words = span.split()
                if words and is_rcb4(words[0]) and len(words) > 1:
                    yield n, span


checked, skipped = 0, collections.Counter()
commands_seen = set()
for path in FILES:
    for n, command in documented_commands(path):
        words = shlex.split(command) if command.count('"') % 2 == 0 else command.split()
        if any(PLACEHOLDER_SYNTAX.search(w) for w in words[1:]):
            skipped["synopsis syntax ([optional], a|b, …, <placeholder>)"] += 1
            continue
        problems, skip, cmd_path = examine(words[1:], strict=True)
        if skip:
            skipped[skip] += 1
            continue
        checked += 1
        commands_seen.add(" ".join(cmd_path))
        check(not problems, f"{rel(path)}:{n}: {command}" + ("" if not problems else ": " + "; ".join(problems)))

inline_checked, inline_skipped = 0, collections.Counter()
for path in FILES:
    for n, span in inline_commands(path):
        words = span.split()
        if any(PLACEHOLDER_SYNTAX.search(w) for w in words[1:]):
            inline_skipped["synopsis syntax ([optional], a|b, …, <placeholder>)"] += 1
            continue
        problems, skip, cmd_path = examine(words[1:], strict=False)
        if skip:
            inline_skipped[skip] += 1
            continue
        inline_checked += 1
        check(not problems, f"{rel(path)}:{n}: `{span}` (inline)" + ("" if not problems else ": " + "; ".join(problems)))

print(f"\ncommand lines in code blocks: {checked} checked, {sum(skipped.values())} skipped")
for why, k in sorted(skipped.items()):
    print(f"  skipped {k}: {why}")
print(f"inline `rcb4 ...` spans: {inline_checked} checked, {sum(inline_skipped.values())} skipped")
for why, k in sorted(inline_skipped.items()):
    print(f"  skipped {k}: {why}")
check(checked >= 20, f"{checked} documented command lines checked (at least 20: the extraction works)")

# --- 3. every command the tool lists is documented in docs/tool.md -----------------------------------

tool_md_path = os.path.join(ROOT, "docs", "tool.md")
check(os.path.isfile(tool_md_path), "docs/tool.md exists")
tool_md = "\n".join(read(tool_md_path)) if os.path.isfile(tool_md_path) else ""
first_cells = []
for line in tool_md.split("\n"):
    if line.startswith("|"):
        cells = re.split(r"(?<!\\)\|", line)
        if len(cells) > 2 and not re.fullmatch(r"[-: ]*", cells[1]):
            first_cells.append(cells[1])
GLOBALS = r"(?:\s+--?[\w-]+(?:[ =](?!-)\S+)?)*"


def mentioned(words):
    if re.search(r"rcb4" + GLOBALS + r"\s+" + r"\s+".join(map(re.escape, words)) + r"(?![\w-])", tool_md):
        return True
    group = re.escape(words[0])
    for cell in first_cells:
        if re.search(r"`" + group + r"(?![\w-])", cell) and (
                len(words) == 1 or re.search(r"(?<![\w-])" + re.escape(words[1]) + r"(?![\w-])", cell)):
            return True
    return False


listed = 0
for name in top.subcommands:
    listed += 1
    check(mentioned([name]), f"docs/tool.md documents `rcb4 {name}`")
    for sub in tool_help([name]).subcommands:
        listed += 1
        check(mentioned([name, sub]), f"docs/tool.md documents `rcb4 {name} {sub}`")
print(f"{listed} commands the tool lists, looked up in docs/tool.md")

finish()
