#!/usr/bin/env python3
"""House rules of the tree that a reader checks in seconds, checked by CTest (layout.check):

  1. No file of harness/ is longer than 500 lines, and no function there longer than 80 lines
     (counted from the line that starts its signature to its closing brace; lambdas count with
     the function that holds them). Exceptions are listed in EXCEPTIONS with the reason.
  2. No header of harness/config/ includes MuJoCo or EGL, directly or through another header of
     the project: configuration is read, written and listed without the simulator.
  3. The libraries planner/, control/ and vo/ include neither MuJoCo, EGL nor yaml-cpp.
  4. Nothing in the repository refers to documents outside it (DESIGN.md, CONVENTIONS.md,
     REFERENCE.md live beside the repository, not in it).

Usage: check_layout.py [ROOT]. Prints one line per violation and exits 1, or exits 0 silently.
"""
import os
import re
import sys

MAX_FILE_LINES = 500
MAX_FUNCTION_LINES = 80
# "path:function" -> why it may be longer. Keep this empty unless a split would hurt.
EXCEPTIONS = {}

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.M)
FORBIDDEN_IN_CONFIG = ("mujoco/", "EGL/", "GL/")
FORBIDDEN_IN_LIBRARIES = ("mujoco/", "EGL/", "GL/", "yaml-cpp/")
OUTSIDE_DOCS = re.compile(r"\b(DESIGN|CONVENTIONS|REFERENCE)\.md\b")


def source_files(root, folder):
    for dirpath, _, files in os.walk(os.path.join(root, folder)):
        for name in sorted(files):
            if name.endswith((".h", ".cpp")):
                yield os.path.join(dirpath, name)


def strip_comments_and_strings(text):
    """The text with comments, string and character literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(name, first line, last line) of every function body in C++ source `text`."""
    code = strip_comments_and_strings(text)
    found, stack = [], []  # stack of (kind, start line, name)
    head_start, line = 0, 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            head = code[head_start:i]
            enclosing = stack[-1][0] if stack else "scope"
            kind, name = "block", ""
            if re.search(r"\bnamespace\b", head) or re.search(r'extern\s*""', head):
                kind = "scope"
            elif re.search(r"\b(class|struct|union|enum)\b[^()]*$", head):
                kind = "scope"
            elif enclosing == "scope" and ")" in head and not re.search(r"=\s*$", head.strip()):
                kind = "function"
                m = re.search(r"([~\w:]+|operator\S+)\s*\(", head)
                name = m.group(1) if m else "?"
            first = line - head.rstrip().count("\n") + head[: len(head) - len(head.lstrip())].count("\n")
            stack.append((kind, first, name))
            head_start = i + 1
        elif c == "}":
            if stack:
                kind, first, name = stack.pop()
                if kind == "function":
                    found.append((name, first, line))
            head_start = i + 1
        elif c == ";":
            head_start = i + 1
    return found


def check_sizes(root, problems):
    for path in source_files(root, "harness"):
        rel = os.path.relpath(path, root)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        lines = text.count("\n")
        if lines > MAX_FILE_LINES:
            problems.append(f"{rel}: {lines} lines (at most {MAX_FILE_LINES})")
        for name, first, last in functions(text):
            length = last - first + 1
            if length > MAX_FUNCTION_LINES and f"{rel}:{name}" not in EXCEPTIONS:
                problems.append(f"{rel}:{first}: function {name} has {length} lines (at most {MAX_FUNCTION_LINES})")


def includes(path):
    with open(path, encoding="utf-8") as f:
        return INCLUDE.findall(f.read())


def check_config_headers(root, problems):
    for path in source_files(root, os.path.join("harness", "config")):
        if not path.endswith(".h"):
            continue
        seen, todo = set(), [os.path.relpath(path, root)]
        while todo:
            header = todo.pop()
            if header in seen:
                continue
            seen.add(header)
            for inc in includes(os.path.join(root, header)):
                if inc.startswith(FORBIDDEN_IN_CONFIG):
                    chain = "" if header == os.path.relpath(path, root) else f" (through {header})"
                    problems.append(f"{os.path.relpath(path, root)}: includes <{inc}>{chain}")
                elif os.path.exists(os.path.join(root, inc)):
                    todo.append(inc)


def check_libraries(root, problems):
    for lib in ("planner", "control", "vo"):
        for path in source_files(root, lib):
            for inc in includes(path):
                if inc.startswith(FORBIDDEN_IN_LIBRARIES):
                    problems.append(f"{os.path.relpath(path, root)}: includes <{inc}> (a pure library)")


def check_references(root, problems):
    for dirpath, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if not d.startswith(".") and not d.startswith("build") and d != "results"]
        for name in files:
            if not name.endswith((".h", ".cpp", ".py", ".sh", ".md", ".txt", ".yaml", ".cmake")):
                continue
            path = os.path.join(dirpath, name)
            if os.path.abspath(path) == os.path.abspath(__file__):
                continue
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, text in enumerate(f, 1):
                    if OUTSIDE_DOCS.search(text):
                        rel = os.path.relpath(path, root)
                        problems.append(f"{rel}:{number}: refers to a document outside the repository")


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    problems = []
    check_sizes(root, problems)
    check_config_headers(root, problems)
    check_libraries(root, problems)
    check_references(root, problems)
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
