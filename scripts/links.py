#!/usr/bin/env python3
"""Every relative link in the repository's Markdown resolves to a file or folder that exists.

    scripts/links.py [ROOT]

Reads every `*.md` file outside `target/` and hidden folders, finds links written as
`[text](path)` or `[text](path#anchor)` that are not web addresses, and checks that the path
exists relative to the file that links it; a link to a `#heading` of a Markdown file checks
that the heading exists too. Exit status 1 on any broken link, with each one listed.
"""

import re
import sys
from pathlib import Path

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
CODE = re.compile(r"```.*?```", re.S)


def anchors(md: Path):
    """GitHub's anchors of a Markdown file's headings."""
    out = set()
    for line in CODE.sub("", md.read_text(encoding="utf-8")).splitlines():
        if line.startswith("#"):
            title = line.lstrip("#").strip().lower()
            slug = re.sub(r"[^\w\- ]", "", title).replace(" ", "-")
            out.add(slug)
    return out


def main(root: Path) -> int:
    broken = []
    files = [
        p for p in root.rglob("*.md")
        if not any(part.startswith(".") or part in ("target", "node_modules") for part in p.relative_to(root).parts)
    ]
    for md in sorted(files):
        text = CODE.sub("", md.read_text(encoding="utf-8"))
        for target in LINK.findall(text):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):
                continue
            path, _, anchor = target.partition("#")
            dest = md if not path else (md.parent / path)
            if not dest.exists():
                broken.append(f"{md.relative_to(root)}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{md.relative_to(root)}: {target} (no such heading)")
    for b in broken:
        print(b)
    print(f"{len(files)} Markdown files, {len(broken)} broken links")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent)))
