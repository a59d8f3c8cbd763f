#!/usr/bin/env bash
# Check the documentation: README.md is at most 250 lines and opens with the two set-up
# commands; every relative link in README.md, ARCHITECTURE.md and docs/ resolves (files and
# #anchors); no page cites a path outside the repository. Exits 1 naming each problem.
# Plain bash and python3's standard library; ctest runs it as the entry `docs`.
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 - "$@" <<'PY'
import pathlib
import re
import sys

root = pathlib.Path.cwd().resolve()
problems = []

def Problem(path, line, what):
    problems.append(f"{path.relative_to(root)}:{line}: {what}")

# README: length and the two set-up commands first.
readme = root / "README.md"
lines = readme.read_text(encoding="utf-8").splitlines()
if len(lines) > 250:
    Problem(readme, len(lines), f"{len(lines)} lines, at most 250")
fence = next((i for i, l in enumerate(lines) if l.startswith("```")), None)
if fence is None or any(l.strip() for l in lines[1:fence] if not l.startswith("# ")):
    Problem(readme, 1, "the title must be followed directly by a code block with the set-up commands")
else:
    block = []
    for l in lines[fence + 1:]:
        if l.startswith("```"):
            break
        block.append(l.split("#")[0].strip())
    if block != ["scripts/demo.sh", "scripts/test.sh"]:
        Problem(readme, fence + 2, f"the first code block must hold scripts/demo.sh and scripts/test.sh, holds {block}")

pages = [readme, root / "ARCHITECTURE.md"] + sorted((root / "docs").rglob("*.md"))

def Anchor(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")

anchorCache = {}

def Anchors(path):
    if path not in anchorCache:
        seen, anchors, inFence = {}, set(), False
        for l in path.read_text(encoding="utf-8").splitlines():
            if l.startswith("```"):
                inFence = not inFence
            m = None if inFence else re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", l)
            if m:
                a = Anchor(m.group(1))
                n = seen.get(a, 0)
                seen[a] = n + 1
                anchors.add(a if n == 0 else f"{a}-{n}")
        anchorCache[path] = anchors
    return anchorCache[path]

link = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
outside = re.compile(r"\.\./shared|/work/")

for page in pages:
    if not page.exists():
        Problem(root / "README.md", 0, f"missing page {page.relative_to(root)}")
        continue
    inFence = False
    for number, l in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        m = outside.search(l)
        if m:
            Problem(page, number, f"cites a path outside the repository ({m.group(0)})")
        if l.startswith("```"):
            inFence = not inFence
            continue
        if inFence:
            continue
        for target in link.findall(re.sub(r"`[^`]*`", "", l)):
            if re.match(r"[a-z][a-z0-9+.-]*:", target):
                continue  # http:, https:, mailto:
            file, _, anchor = target.partition("#")
            resolved = (page.parent / file).resolve() if file else page
            if root not in resolved.parents and resolved != root:
                Problem(page, number, f"link {target} leaves the repository")
                continue
            if not resolved.exists():
                Problem(page, number, f"link {target}: no file {resolved.relative_to(root)}")
                continue
            if anchor and (resolved.suffix != ".md" or anchor not in Anchors(resolved)):
                Problem(page, number, f"link {target}: no heading #{anchor} in {resolved.relative_to(root)}")

for p in problems:
    print(f"check_docs: {p}", file=sys.stderr)
print(f"check_docs: {len(pages)} pages, {len(problems)} problems")
sys.exit(1 if problems else 0)
PY
