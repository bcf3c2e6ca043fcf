#!/usr/bin/env python3
"""Every relative link of the README and docs/ points to a file that exists.

Checks markdown links and images, `[text](target)` and `![alt](target)`, in README.md,
CHANGELOG.md and docs/**/*.md: a target without a scheme (not http:, https:, mailto:) and not
only an anchor (#...) must name an existing file or directory, relative to the page. Prints one
line per broken link (page:line: target) and exits 1 if there is any.

  python3 scripts/check_links.py [ROOT]
"""

import pathlib
import re
import sys

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def pages(root):
    yield from (root / name for name in ("README.md", "CHANGELOG.md") if (root / name).exists())
    yield from sorted((root / "docs").rglob("*.md"))


def broken(root):
    for page in pages(root):
        in_code = False
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if line.lstrip().startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            for target in LINK.findall(line):
                if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                    continue
                path = target.split("#", 1)[0]
                if not (page.parent / path).exists():
                    yield f"{page.relative_to(root)}:{number}: {target}"


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parents[1])
    found = list(broken(root.resolve()))
    for b in found:
        print(b)
    print(f"links: {len(found)} broken", file=sys.stderr)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
