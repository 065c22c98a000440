"""Every relative link of the user documents (README.md, docs/*.md, benchmarks/README.md, the
example plugin's README) leads somewhere: the file exists and, for ``#anchor``, the target page has
a heading with that anchor as GitHub makes it. Links inside fenced code are not links."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PAGES = [
    REPO / "README.md",
    *sorted((REPO / "docs").glob("*.md")),
    REPO / "benchmarks" / "README.md",
    REPO / "plugins" / "physbench-scipy" / "README.md",
]

FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"`[^`]*`")
# [text](target) or ![alt](target "title"); the text may hold code spans with brackets removed.
LINK = re.compile(r"\[[^\]]*\]\(\s*([^)\s]+)(?:\s+\"[^\"]*\")?\s*\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
EXTERNAL = re.compile(r"^[a-z][a-z0-9+.-]*:", re.I)  # http:, https:, mailto:


def prose_lines(path: Path) -> list[tuple[int, str]]:
    """The (line number, text) pairs of ``path`` outside fenced code blocks."""
    lines, fenced = [], False
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced:
            lines.append((number, line))
    return lines


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: link markup reduced to its text, lower case, punctuation
    dropped (letters, digits, ``_``, ``-`` and spaces stay), spaces turned into hyphens."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading).lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """Every heading anchor of ``path``, repeated headings numbered ``-1``, ``-2`` as on GitHub."""
    found: set[str] = set()
    seen: dict[str, int] = {}
    for _, line in prose_lines(path):
        match = HEADING.match(line)
        if not match:
            continue
        base = slug(match.group(2))
        count = seen.get(base, 0)
        seen[base] = count + 1
        found.add(base if count == 0 else f"{base}-{count}")
    return found


def relative_links(path: Path) -> list[tuple[int, str]]:
    """The relative link targets of ``path`` (external URLs left out), with their line numbers."""
    links = []
    for number, line in prose_lines(path):
        # Code spans may hold "](" (e.g. a regex); a link's text keeps working without them.
        for target in LINK.findall(CODE_SPAN.sub("", line)):
            if not EXTERNAL.match(target):
                links.append((number, target))
    return links


def broken_links(path: Path) -> list[str]:
    """One message per relative link of ``path`` whose file or heading anchor does not exist."""
    problems = []
    for number, target in relative_links(path):
        file_part, _, anchor = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path
        where = f"{path.relative_to(path.parents[1])}:{number}: {target}"
        if not dest.exists():
            problems.append(f"{where}: no file {dest}")
        elif anchor and (dest.suffix != ".md" or anchor not in anchors(dest)):
            problems.append(f"{where}: no heading #{anchor} in {dest.name}")
    return problems


def test_every_relative_link_of_the_documents_resolves() -> None:
    links = [(page, target) for page in PAGES for _, target in relative_links(page)]
    # The documents link to each other heavily; finding few links means the parser broke.
    assert len(links) >= 50, links
    assert sum("#" in target for _, target in links) >= 20, links
    problems = [problem for page in PAGES for problem in broken_links(page)]
    assert not problems, "\n".join(problems)


def test_the_readme_links_every_docs_page_and_each_page_links_back() -> None:
    readme_targets = {
        (REPO / target.partition("#")[0]).resolve()
        for _, target in relative_links(REPO / "README.md")
    }
    for page in sorted((REPO / "docs").glob("*.md")):
        assert page.resolve() in readme_targets, f"README.md does not link {page.name}"
    for name in ("results.md", "architecture.md"):
        targets = [t for _, t in relative_links(REPO / "docs" / name)]
        assert any(t.startswith("../README.md") for t in targets), f"{name} has no link back"


def test_a_missing_file_or_heading_is_reported_and_fenced_code_is_skipped(tmp_path: Path) -> None:
    (tmp_path / "docs").mkdir()
    other = tmp_path / "docs" / "other.md"
    other.write_text("# Other page\n\n## Results at a glance\n\n## Results at a glance\n")
    page = tmp_path / "docs" / "page.md"
    page.write_text(
        "# Page\n\n## Its own `section`\n\n"
        "[ok](other.md) [ok anchor](other.md#results-at-a-glance-1) [self](#its-own-section)\n"
        "[gone](missing.md) [bad anchor](other.md#no-such-heading) [web](https://example.org/x)\n"
        "```bash\n[in code](nowhere.md)\n```\n"
        "`[span](nowhere.md)` ![image](other.md)\n"
    )
    assert len(relative_links(page)) == 6
    problems = broken_links(page)
    assert len(problems) == 2, problems
    assert "missing.md" in problems[0] and "no file" in problems[0]
    assert "#no-such-heading" in problems[1] and "other.md" in problems[1]


def test_heading_anchors_are_githubs() -> None:
    assert slug("Learned estimator (`resnet3d`)") == "learned-estimator-resnet3d"
    assert slug("From a camera's video: measured") == "from-a-cameras-video-measured"
    assert slug("Test a plugin: conformance kits") == "test-a-plugin-conformance-kits"
    assert slug("Sweeps: `physbench bench`, `plot`") == "sweeps-physbench-bench-plot"
    assert slug("Ball drops (11 balls × 2 drops)") == "ball-drops-11-balls--2-drops"
