#!/usr/bin/env python3
"""Every relative link in README.md and docs/*.md resolves: the file (or folder) exists, and an
anchor (#...) names a heading of the target page (GitHub's slugs). Usage: check_links.py SOURCE_DIR"""
import pathlib
import re
import sys
import unicodedata

root = pathlib.Path(sys.argv[1]).resolve()  # a relative SOURCE_DIR too
pages = [root / "README.md"] + sorted((root / "docs").glob("*.md"))
link = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
fence = re.compile(r"^(```|~~~)")


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, markup and punctuation dropped, spaces to '-'."""
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = text.lower()
    out = []
    for ch in text:
        cat = unicodedata.category(ch)
        if ch in " -":
            out.append("-" if ch == " " else ch)
        elif ch == "_" or cat[0] in "LN" or cat == "Mn":
            out.append(ch)
    return "".join(out)


def anchors(page: pathlib.Path) -> set:
    found, counts, in_code = set(), {}, False
    for line in page.read_text(encoding="utf-8").splitlines():
        if fence.match(line.strip()):
            in_code = not in_code
            continue
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m and not in_code:
            s = slug(m.group(1))
            n = counts.get(s, 0)
            counts[s] = n + 1
            found.add(s if n == 0 else f"{s}-{n}")
    for m in re.finditer(r'<a\s+(?:name|id)="([^"]+)"', page.read_text(encoding="utf-8")):
        found.add(m.group(1))
    return found


bad = []
checked = 0
for page in pages:
    in_code = False
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        if fence.match(line.strip()):
            in_code = not in_code
            continue
        if in_code:
            continue
        for m in link.finditer(re.sub(r"`[^`]*`", "", line)):
            target = m.group(1)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
                continue
            path, _, anchor = target.partition("#")
            dest = (page.parent / path).resolve() if path else page
            checked += 1
            where = f"{page.relative_to(root)}:{number}: link '{target}'"
            try:
                dest.relative_to(root.resolve())
            except ValueError:
                bad.append(f"{where} leaves the repository")
                continue
            if not dest.exists():
                bad.append(f"{where}: {path} does not exist")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                bad.append(f"{where}: no heading '#{anchor}' in {dest.relative_to(root.resolve())}")

print(f"check_links: {checked} relative links in {len(pages)} pages")
for b in bad:
    print(b)
sys.exit(1 if bad or checked == 0 else 0)
