#!/usr/bin/env python3
"""Checks that every relative link in README.md and docs/*.md resolves to a file or folder of
the checkout. Prints each broken one as FILE:LINE: TARGET and exits 1 when there is any.
Run by scripts/test.sh (CI); usage: python3 scripts/check_links.py [ROOT]"""

import pathlib
import re
import sys

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def broken_links(root):
    pages = [root / "README.md", *sorted((root / "docs").glob("*.md"))]
    for page in pages:
        in_code = False
        for number, line in enumerate(page.read_text().splitlines(), 1):
            if line.lstrip().startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            for target in LINK.findall(line):
                if re.match(r"[a-z]+:", target) or target.startswith("#"):
                    continue  # a URL or an anchor on the page itself
                path = (page.parent / target.split("#", 1)[0]).resolve()
                if not path.exists():
                    yield f"{page.relative_to(root)}:{number}: {target}"


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    broken = list(broken_links(root))
    for entry in broken:
        print(f"check_links: broken link {entry}")
    print(f"check_links: {'ok' if not broken else str(len(broken)) + ' broken'}")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
