#!/usr/bin/env python3
"""Checks that the C++ a reader has to hold stays small: no source file under src/, apps/,
python/ or bench/ is longer than 500 lines, and no function (free, member, defined in a class
or out of it) is longer than 80 lines, counted from the first line of its signature to its
closing brace. The exceptions are listed in scripts/size_exceptions.txt, each with the most
lines it may have and its reason: an exception may shrink but not grow, and one that no longer
applies is reported too, so the list cannot go stale.
Prints each violation and exits 1 if there is any.   Usage: check_sizes.py [SOURCE_DIR]"""
import os
import re
import sys

MAX_FILE_LINES = 500
MAX_FUNCTION_LINES = 80
DIRS = ["src", "apps", "python", "bench"]
EXTENSIONS = (".h", ".cpp", ".inl")

root = sys.argv[1] if len(sys.argv) > 1 else os.getcwd()


def strip_code(text):
    """The text with comments, string and character literals blanked (newlines kept), so that
    braces inside them are not counted."""
    out = []
    i, n = 0, len(text)
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
        elif c == "R" and text.startswith('R"', i) and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i and text[i - 1].isalnum():  # a digit separator: 1'000'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


SCOPE = re.compile(r"^(namespace\b|extern\b|(template\s*<[^{]*>\s*)?(class|struct|union)\b[^()]*$)")


def functions(text):
    """(name, first line, last line) of every function body directly in a namespace or a class
    (lambdas and blocks inside a function count towards that function)."""
    code = strip_code(text)
    found = []
    stack = []  # per open brace: ("function", name, first line), ("scope",) or ("other",)
    head_start = 0  # where the current head began: after the last ; { or }
    for i, c in enumerate(code):
        if c == "{":
            raw = code[head_start:i]
            head = " ".join(raw.split())
            if any(e[0] == "function" for e in stack):
                stack.append(("other",))
            elif SCOPE.match(head):
                stack.append(("scope",))
            elif "(" in head and not head.endswith("="):
                m = re.search(r"(operator\s*[^\s(]+|[~\w:]+)\s*\(", head)
                first = text.count("\n", 0, head_start + len(raw) - len(raw.lstrip())) + 1
                stack.append(("function", m.group(1) if m else "?", first))
            else:
                stack.append(("other",))
            head_start = i + 1
        elif c == "}":
            if stack:
                entry = stack.pop()
                if entry[0] == "function":
                    found.append((entry[1], entry[2], text.count("\n", 0, i) + 1))
            head_start = i + 1
        elif c == ";" or (c == ":" and code[i - 1:i + 1] != "::" and code[i:i + 2] != "::"
                          and re.search(r"\b(public|private|protected)\s*$", code[head_start:i])):
            head_start = i + 1
        elif c == "#" and (i == 0 or code[i - 1] == "\n"):
            # A preprocessor line is not part of the next head.
            j = code.find("\n", i)
            head_start = len(code) if j < 0 else j + 1
    return found


def load_exceptions(path):
    """{(file, function): (most lines, reason)} from lines "file:function LINES reason"
    (function "*": the file's length; # starts a comment)."""
    out = {}
    if not os.path.exists(path):
        return out
    for k, line in enumerate(open(path, encoding="utf-8"), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.split(None, 2)
        if len(parts) < 3 or ":" not in parts[0] or not parts[1].isdigit():
            print(f"{path}:{k}: expected 'file:function LINES reason'")
            sys.exit(2)
        f, fn = parts[0].rsplit(":", 1)
        out[(f, fn)] = (int(parts[1]), parts[2])
    return out


exceptions = load_exceptions(os.path.join(root, "scripts", "size_exceptions.txt"))
used = set()
errors = []
files = 0
for top in DIRS:
    for d, _, names in sorted(os.walk(os.path.join(root, top))):
        for n in sorted(names):
            if not n.endswith(EXTENSIONS):
                continue
            path = os.path.join(d, n)
            rel = os.path.relpath(path, root)
            text = open(path, encoding="utf-8").read()
            files += 1
            lines = text.count("\n")
            measured = [((rel, "*"), lines, MAX_FILE_LINES, f"{rel}: {lines} lines")]
            measured += [((rel, name), last - first + 1, MAX_FUNCTION_LINES,
                          f"{rel}:{first}: function {name} is {last - first + 1} lines")
                         for name, first, last in functions(text)]
            for key, length, limit, what in measured:
                if length <= limit:
                    continue
                if key in exceptions:
                    used.add(key)
                    most = exceptions[key][0]
                    if length > most:
                        errors.append(f"{what}, more than the {most} its exception allows "
                                      "(scripts/size_exceptions.txt): split it")
                else:
                    errors.append(f"{what} (at most {limit})")
for key in sorted(set(exceptions) - used):
    errors.append(f"scripts/size_exceptions.txt: {key[0]}:{key[1]} is listed but is not too long "
                  "(remove it)")
for e in errors:
    print(e)
print(f"sizes: {files} files, {len(exceptions)} exceptions, {len(errors)} violations")
sys.exit(1 if errors else 0)
