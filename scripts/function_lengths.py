#!/usr/bin/env python3
"""Lists C++ functions longer than a limit (lines from the body's opening brace to its closing one).

    scripts/function_lengths.py [--max N] FILE_OR_DIR...

Exit 1 when any function is longer than N (default 60), printing file:line, name and length.
A function is a brace block whose head (the text since the previous ';', '{' or '}') ends in a
parameter list, optionally followed by qualifiers, a trailing return type or a constructor's
initialiser list; blocks of control statements, lambdas and classes are part of their function.
Comments, string and character literals are blanked first, so braces inside them do not count.
"""
import os
import re
import sys

CONTROL = re.compile(r"^(if|for|while|switch|catch|else|do|return|case)\b")
HEAD = re.compile(r"\)\s*(const|noexcept|override|final|mutable|&|&&|\s)*(->[^{]*)?$")


def blank(text):
    """Replaces comments and literals by spaces, keeping line breaks."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = ")" + (m.group(1) if m else "") + '"'
            j = text.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def is_function_head(head):
    h = " ".join(head.split())
    if not h or CONTROL.match(h) or h.endswith("]") or "=" in h.split("(")[0]:
        return False
    if re.match(r"^(template\s*<.*>\s*)?(class|struct|union|enum|namespace)\b", h):
        return False
    # A constructor's initialiser list: the head's parameter list comes before ':'.
    m = re.match(r"^(.*?\))\s*:\s*[A-Za-z_].*$", h)
    if m and HEAD.search(m.group(1)):
        return True
    return bool(HEAD.search(h)) and "(" in h


def functions(path):
    text = blank(open(path, encoding="utf-8").read())
    found, stack, head_start = [], [], 0
    line = 1
    line_at = []
    for c in text:
        line_at.append(line)
        if c == "\n":
            line += 1
    depth_fn = None  # index in stack of the open function block
    for i, c in enumerate(text):
        if c == "{":
            head = text[head_start:i]
            fn = depth_fn is None and is_function_head(head.split("#")[-1] if "#" in head else head)
            stack.append((i, fn, head))
            if fn:
                depth_fn = len(stack) - 1
            head_start = i + 1
        elif c == "}":
            if stack:
                start, fn, head = stack.pop()
                if fn:
                    name = " ".join(head.split())
                    name = name[: name.find("(")].split()[-1] if "(" in name else name
                    found.append((line_at[start], line_at[i] - line_at[start] + 1, name))
                    depth_fn = None
            head_start = i + 1
        elif c == ";":
            head_start = i + 1
    return found


def main(argv):
    limit = 60
    if len(argv) > 1 and argv[0] == "--max":
        limit, argv = int(argv[1]), argv[2:]
    files = []
    for a in argv:
        if os.path.isdir(a):
            for root, _, names in os.walk(a):
                files += [os.path.join(root, f) for f in sorted(names)
                          if f.endswith((".h", ".cpp"))]
        else:
            files.append(a)
    long = []
    for f in sorted(files):
        for line, length, name in functions(f):
            if length > limit:
                long.append(f"{f}:{line}: {name}: {length} lines (limit {limit})")
    print("\n".join(long) if long else f"no function over {limit} lines in {len(files)} files")
    return 1 if long else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
