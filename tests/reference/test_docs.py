"""The documentation's figures against the committed files they come from.

Standard library and pytest only: `python3 -m pytest tests/reference/test_docs.py -q`
(VF_ROOT, if set, is the repository root).

Checked documents: README.md, docs/*.md and assets/README.md (figures and links),
CHANGELOG.md (links only: it is history, its numbers are those of past builds).

Conventions (docs/reports.md, *Figures in the documentation*):

* A table that shows measured figures is preceded by a marker
  `<!-- figures {JSON} -->` naming the file and how its rows and columns map:

      {"file": "benches/results/X.csv",        # CSV, or JSON with "rows": "dotted.path"
       "key": "mesh",                           # file field(s) matched to the key column(s)
       "key_cols": ["mesh"],                    # table header(s) of the key (default: first)
       "keys": {"table text": "file value"},    # optional renaming of key values
       "where": {"method": "ours"},             # optional filter on the file's rows
       "columns": {"HEADER": ["field", ...]},   # one field per number in the cell, in order
       "text": ["HEADER", ...]}                 # columns with digits that are not figures

  A field is `name`, `name*100` (scaled), `name#0` (the first number inside a text
  value), or null (a number not checked, e.g. a parameter). A column may instead map to
  {"file": ..., "where": ..., "key": ..., "rows": ..., "fields": [...]} to take its
  figures from another file or other rows. Every number in every mapped cell is
  compared with the file's value rounded to the digits the cell shows; a table row
  whose key the file lacks fails, and so does a column with digits that is neither
  mapped, a key, nor listed in "text".
* A table with a decimal number and no figures marker fails unless it is preceded by
  `<!-- no-figures: why -->` (a table of settings or defaults, not measurements).
* A measured number in prose is followed by `<!-- fig FILE SELECTOR -->`: SELECTOR is
  a dotted path into a JSON file (`wall_seconds`, `results.0.ratio`, optionally
  `*factor`), or for a CSV
  `col=value,col=value:field` (one row). The number just before the marker is checked.
* Every file named by a marker has a sidecar `FILE.provenance.json` with a non-empty
  "command" and a "commit" (7-40 hex digits, present in the repository when git is).
* Every relative link in README.md, CHANGELOG.md and docs/*.md points at an existing
  file, and a `#anchor` into a Markdown file at one of its headings.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import tempfile
import unicodedata
from pathlib import Path

ROOT = Path(os.environ.get("VF_ROOT", Path(__file__).resolve().parents[2]))

FIGURE_DOCS = ["README.md", "docs/*.md", "assets/README.md"]
LINK_DOCS = ["README.md", "CHANGELOG.md", "docs/*.md", "assets/README.md"]

MARKER = re.compile(r"<!--\s*figures\s+(\{.*?\})\s*-->", re.S)
NO_FIGURES = re.compile(r"<!--\s*no-figures:.*?-->", re.S)
INLINE = re.compile(r"<!--\s*fig\s+(\S+)\s+(\S+)\s*-->")
NUMBER = re.compile(r"(?<![\w.])(\d{1,3}(?:,\d{3})+|\d+)(\.\d+)?(?:e([+-]?\d+))?(?![\w])")
DECIMAL = re.compile(r"\d\.\d")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
HEX = re.compile(r"^[0-9a-f]{7,40}$")


def docs(root, patterns):
    out = []
    for p in patterns:
        out += sorted(root.glob(p))
    return [p for p in out if p.is_file()]


def numbers(text):
    """(value, half-unit of the last digit shown) of every number in text."""
    text = re.sub(r"\]\([^)]*\)", "]", text)  # link targets are not figures
    text = text.replace("*", "").replace("`", "").replace("\u2212", "-")
    out = []
    for m in NUMBER.finditer(text):
        whole, frac, exp = m.group(1), m.group(2) or "", m.group(3)
        v = float(whole.replace(",", "") + frac)
        decimals = len(frac) - 1 if frac else 0
        if exp is not None:
            v *= 10.0 ** int(exp)
            decimals -= int(exp)
        out.append((v, 0.5 * 10.0 ** (-decimals)))
    return out


def close(shown, half, value):
    return abs(shown - value) <= half * (1 + 1e-9) + 1e-12 * max(1.0, abs(value))


# ---------------------------------------------------------------- data files


class DataError(Exception):
    pass


def dig(obj, path):
    for part in [p for p in path.split(".") if p]:
        if isinstance(obj, list):
            obj = obj[int(part)]
        elif isinstance(obj, dict) and part in obj:
            obj = obj[part]
        else:
            raise DataError(f"no {part!r} in path {path!r}")
    return obj


def load_rows(root, file, rows_path=None):
    p = root / file
    if not p.is_file():
        raise DataError(f"{file}: no such file")
    if p.suffix == ".csv":
        with open(p, newline="") as f:
            return list(csv.DictReader(f))
    if p.suffix == ".json":
        data = json.loads(p.read_text())
        rows = dig(data, rows_path or "")
        if not isinstance(rows, list):
            raise DataError(f"{file}: {rows_path!r} is not a list of rows")
        return rows
    raise DataError(f"{file}: only .csv and .json files can back figures")


def field_value(row, spec):
    m = re.fullmatch(r"([^#*]+)(?:#(\d+))?(?:\*([0-9.eE+-]+))?", spec)
    if not m:
        raise DataError(f"bad field spec {spec!r}")
    name, idx, scale = m.groups()
    if name not in row:
        raise DataError(f"no field {name!r}")
    v = row[name]
    if idx is not None:
        found = numbers(str(v))
        if len(found) <= int(idx):
            raise DataError(f"field {name!r} = {v!r} has no number #{idx}")
        v = found[int(idx)][0]
    if isinstance(v, bool) or v in ("", None):
        raise DataError(f"field {name!r} is empty or not a number")
    v = float(v)
    return v * float(scale) if scale else v


def matches(row, where):
    return all(str(row.get(k)) == str(v) for k, v in (where or {}).items())


def provenance_errors(root, file, seen):
    if file in seen:
        return []
    seen.add(file)
    side = root / (file + ".provenance.json")
    if not side.is_file():
        return [f"{file}: no provenance ({side.name} beside it naming the command and the commit)"]
    try:
        prov = json.loads(side.read_text())
    except json.JSONDecodeError as e:
        return [f"{side}: not JSON ({e})"]
    errs = []
    if not str(prov.get("command", "")).strip():
        errs.append(f"{side}: no command")
    commit = str(prov.get("commit", ""))
    if not HEX.match(commit):
        errs.append(f"{side}: commit {commit!r} is not a commit hash")
    elif (root / ".git").exists() and shutil.which("git"):
        r = subprocess.run(["git", "-C", str(root), "cat-file", "-e", commit + "^{commit}"],
                           capture_output=True)
        if r.returncode != 0:
            errs.append(f"{side}: commit {commit} is not in the repository")
    return errs


# ---------------------------------------------------------------- tables


def split_row(line):
    s = line.strip()
    if s.startswith("|"):
        s = s[1:]
    if s.endswith("|"):
        s = s[:-1]
    return [c.strip() for c in re.split(r"(?<!\\)\|", s)]


def tables(text):
    """(start line index, header cells, body rows as (line no, cells)) of every table."""
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        if lines[i].lstrip().startswith("|") and i + 1 < len(lines) and re.match(r"^\s*\|?\s*:?-{3,}", lines[i + 1]):
            header = split_row(lines[i])
            body = []
            j = i + 2
            while j < len(lines) and lines[j].lstrip().startswith("|"):
                body.append((j + 1, split_row(lines[j])))
                j += 1
            yield i, header, body
            i = j
        else:
            i += 1


def marker_before(lines, start):
    """The comment just above a table (blank lines allowed): ('figures', spec) / ('none',) / None."""
    j = start - 1
    while j >= 0 and not lines[j].strip():
        j -= 1
    if j < 0 or not lines[j].rstrip().endswith("-->"):
        return None
    k = j
    while k >= 0 and "<!--" not in lines[k]:
        k -= 1
    comment = "\n".join(lines[k:j + 1])
    m = MARKER.search(comment)
    if m:
        return ("figures", m.group(1))
    if NO_FIGURES.search(comment):
        return ("none",)
    return None


def clean_key(s):
    return re.sub(r"[*`]", "", s).strip()


def check_table(root, where, header, body, spec, seen):
    errs = []
    base_file = spec.get("file")
    if not base_file:
        return [f"{where}: figures marker without \"file\""]
    key_fields = spec.get("key", "mesh")
    key_fields = [key_fields] if isinstance(key_fields, str) else list(key_fields)
    key_cols = spec.get("key_cols", [header[0]])
    renames = spec.get("keys", {})
    columns = spec.get("columns", {})
    text_cols = set(spec.get("text", []))
    for h in list(columns) + list(key_cols) + list(text_cols):
        if h not in header:
            errs.append(f"{where}: marker names column {h!r}, which the table lacks (has {header})")
    if errs:
        return errs
    for h in header:
        if h in columns or h in key_cols or h in text_cols:
            continue
        if any(re.search(r"\d", row[header.index(h)]) for _, row in body if len(row) == len(header)):
            errs.append(f"{where}: column {h!r} holds digits but the figures marker neither maps it nor lists it in \"text\"")
    cache = {}

    def rows_of(file, rows_path):
        if (file, rows_path) not in cache:
            cache[(file, rows_path)] = load_rows(root, file, rows_path)
            errs.extend(provenance_errors(root, file, seen))
        return cache[(file, rows_path)]

    for lineno, cells in body:
        if len(cells) != len(header):
            errs.append(f"{where}, line {lineno}: {len(cells)} cells, header has {len(header)}")
            continue
        key_vals = [clean_key(cells[header.index(c)]) for c in key_cols]
        key_vals = [str(renames.get(v, v)) for v in key_vals]
        for h, cspec in columns.items():
            if isinstance(cspec, list):
                cspec = {"fields": cspec}
            file = cspec.get("file", base_file)
            rows_path = cspec.get("rows", spec.get("rows") if file == base_file else None)
            cwhere = cspec.get("where", spec.get("where", {}) if file == base_file else {})
            ckey = cspec.get("key", key_fields)
            ckey = [ckey] if isinstance(ckey, str) else list(ckey)
            try:
                rows = rows_of(file, rows_path)
            except DataError as e:
                errs.append(f"{where}: {e}")
                continue
            hits = [r for r in rows if matches(r, cwhere) and [str(r.get(k)) for k in ckey] == key_vals]
            if len(hits) != 1:
                errs.append(f"{where}, line {lineno}: {len(hits)} rows of {file} with {dict(zip(ckey, key_vals))} and {cwhere} (need exactly 1)")
                continue
            shown = numbers(cells[header.index(h)])
            fields = cspec["fields"]
            if len(shown) != len(fields):
                errs.append(f"{where}, line {lineno}, column {h!r}: {len(shown)} numbers in {cells[header.index(h)]!r}, the marker maps {len(fields)}")
                continue
            for (v, half), f in zip(shown, fields):
                if f is None:
                    continue
                try:
                    want = field_value(hits[0], f)
                except (DataError, ValueError) as e:
                    errs.append(f"{where}, line {lineno}, column {h!r}: {file}: {e}")
                    continue
                if not close(v, half, want):
                    errs.append(f"{where}, line {lineno}, {key_vals} column {h!r}: shows {v:g}, {file} field {f} is {want:.6g}")
    return errs


def check_inline(root, where, text, seen):
    errs = []
    for m in INLINE.finditer(text):
        if text[max(0, m.start() - 1):m.start()] == "`":
            continue  # a marker quoted as code, not a marker
        file, sel = m.group(1), m.group(2)
        lineno = text.count("\n", 0, m.start()) + 1
        before = numbers(text[max(0, m.start() - 40):m.start()])
        if not before:
            errs.append(f"{where}, line {lineno}: fig marker with no number before it")
            continue
        v, half = before[-1]
        try:
            p = root / file
            if p.suffix == ".json":
                path, _, scale = sel.partition("*")
                want = float(dig(json.loads(p.read_text()), path)) * float(scale or 1)
            else:
                cond, _, f = sel.rpartition(":")
                flt = dict(kv.split("=", 1) for kv in cond.split(",") if kv)
                hits = [r for r in load_rows(root, file) if matches(r, flt)]
                if len(hits) != 1:
                    raise DataError(f"{len(hits)} rows match {flt}")
                want = field_value(hits[0], f)
        except (DataError, ValueError, OSError, IndexError, TypeError) as e:
            errs.append(f"{where}, line {lineno}: {file} {sel}: {e}")
            continue
        errs.extend(provenance_errors(root, file, seen))
        if not close(v, half, want):
            errs.append(f"{where}, line {lineno}: shows {v:g}, {file} {sel} is {want:.6g}")
    return errs


def figure_errors(root, doc_paths):
    errs, seen = [], set()
    for p in doc_paths:
        text = p.read_text()
        lines = text.split("\n")
        rel = p.relative_to(root) if p.is_relative_to(root) else p
        for start, header, body in tables(text):
            where = f"{rel}:{start + 1}"
            mk = marker_before(lines, start)
            if mk is None:
                if any(DECIMAL.search(c) for _, row in body for c in row):
                    errs.append(f"{where}: table with decimal numbers but no <!-- figures {{...}} --> or <!-- no-figures: ... --> marker")
                continue
            if mk[0] == "none":
                continue
            try:
                spec = json.loads(mk[1])
            except json.JSONDecodeError as e:
                errs.append(f"{where}: figures marker is not JSON: {e}")
                continue
            errs.extend(check_table(root, where, header, body, spec, seen))
        errs.extend(check_inline(root, str(rel), text, seen))
    return errs


# ---------------------------------------------------------------- links


def slug(heading):
    h = re.sub(r"<[^>]+>", "", heading).strip().lower()
    h = h.replace("`", "")
    h = "".join(c for c in h if c in " -_" or unicodedata.category(c)[0] in "LN")
    return h.replace(" ", "-")


def anchors(md_path):
    out, counts = set(), {}
    in_code = False
    for line in md_path.read_text().split("\n"):
        if line.startswith("```"):
            in_code = not in_code
        if in_code:
            continue
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m:
            s = slug(m.group(1))
            n = counts.get(s, 0)
            counts[s] = n + 1
            out.add(s if n == 0 else f"{s}-{n}")
    return out


def link_errors(root, doc_paths):
    errs = []
    for p in doc_paths:
        text = p.read_text()
        text = re.sub(r"```.*?```", "", text, flags=re.S)
        for m in LINK.finditer(text):
            target = m.group(1)
            if re.match(r"^[a-z]+:", target):
                continue
            path, _, anchor = target.partition("#")
            dest = (p.parent / path).resolve() if path else p
            if not dest.exists():
                errs.append(f"{p.relative_to(root)}: link {target!r}: no such file")
                continue
            if anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                errs.append(f"{p.relative_to(root)}: link {target!r}: no heading #{anchor} in {dest.name}")
    return errs


# ---------------------------------------------------------------- tests


def test_readme_is_a_front_door():
    lines = (ROOT / "README.md").read_text().split("\n")
    assert len(lines) <= 300, f"README.md has {len(lines)} lines; the reference goes under docs/"


def test_every_figure_matches_its_file():
    errs = figure_errors(ROOT, docs(ROOT, FIGURE_DOCS))
    assert not errs, "\n".join(errs)


def test_every_marked_file_exists_and_some_tables_are_checked():
    text = "\n".join(p.read_text() for p in docs(ROOT, FIGURE_DOCS))
    assert len(MARKER.findall(text)) >= 5, "the figure tables lost their markers"


def test_every_relative_link_resolves():
    errs = link_errors(ROOT, docs(ROOT, LINK_DOCS))
    assert not errs, "\n".join(errs)


HELP_PAGES = ["", "batch", "view", "info", "convert", "sample", "query", "delaunay", "crust", "eval", "study",
              "mnist train", "mnist eval", "mnist tsne", "mnist interpolate", "mnist run", "mnist bench"]


def test_every_flag_of_the_cli_is_documented():
    """Every long option `--help` lists appears in docs/cli.md (skipped without a built binary)."""
    import pytest

    binary = Path(os.environ.get("VF_BIN", ROOT / "target" / "ci" / "voronoi-fit"))
    if not binary.is_file():
        pytest.skip(f"no binary at {binary}")
    cli = (ROOT / "docs" / "cli.md").read_text()
    missing = []
    for page in HELP_PAGES:
        r = subprocess.run([str(binary), *page.split(), "--help"], capture_output=True, text=True, check=True)
        for flag in sorted(set(re.findall(r"(?<![\w-])--[a-z][a-z0-9-]+", r.stdout))):
            if flag not in ("--help",) and flag not in cli:
                missing.append(f"voronoi-fit {page} {flag}".replace("  ", " "))
    assert not missing, "flags missing from docs/cli.md:\n" + "\n".join(missing)


def _altered_copy(doc, old, new):
    """A copy of doc with the first occurrence of old (on a marked line) replaced."""
    text = doc.read_text()
    assert old in text, f"{old!r} not in {doc}"
    tmp = Path(tempfile.mkdtemp()) / doc.name
    tmp.write_text(text.replace(old, new, 1))
    return tmp


def _first_checked_cell(doc):
    """A (line, number text) of a checked figure in doc's first marked table."""
    text = doc.read_text()
    lines = text.split("\n")
    for start, header, body in tables(text):
        mk = marker_before(lines, start)
        if mk and mk[0] == "figures":
            spec = json.loads(mk[1])
            for h, cspec in spec["columns"].items():
                fields = cspec if isinstance(cspec, list) else cspec["fields"]
                if fields and fields[0] is not None:
                    cell = body[0][1][header.index(h)]
                    m = NUMBER.search(cell.replace("*", ""))
                    return lines[body[0][0] - 1], cell, m.group(0)
    raise AssertionError(f"no checked table in {doc}")


def test_checker_fails_on_a_wrong_table_figure():
    doc = ROOT / "README.md"
    line, cell, num = _first_checked_cell(doc)
    assert not figure_errors(ROOT, [doc]), "README must pass before the self-test alters it"
    digits = [i for i, c in enumerate(num) if c.isdigit()]
    i = digits[-1]
    wrong = num[:i] + str((int(num[i]) + 3) % 10) + num[i + 1:]
    altered = line.replace(cell, cell.replace(num, wrong, 1), 1)
    tmp = _altered_copy(doc, line, altered)
    errs = figure_errors(ROOT, [tmp])
    assert errs and any("shows" in e for e in errs), f"changing {num} to {wrong} was not caught: {errs}"


def test_checker_fails_on_an_unmarked_figure_table_and_a_wrong_prose_figure():
    tmp = Path(tempfile.mkdtemp())
    (tmp / "data.json").write_text(json.dumps({"wall_seconds": 2027.36}))
    (tmp / "data.json.provenance.json").write_text(json.dumps({"command": "x", "commit": "0000000"}))
    doc = tmp / "doc.md"
    doc.write_text("Took 2,027 s<!-- fig data.json wall_seconds -->.\n\n| a | b |\n|---|---|\n| x | 1.5 |\n")
    errs = figure_errors(tmp, [doc])
    assert len(errs) == 1 and "no <!-- figures" in errs[0], errs
    doc.write_text("Took 1,314 s<!-- fig data.json wall_seconds -->.\n")
    errs = figure_errors(tmp, [doc])
    assert errs and "shows 1314" in errs[0], errs


def test_checker_fails_without_provenance_and_on_a_missing_row():
    tmp = Path(tempfile.mkdtemp())
    (tmp / "r.csv").write_text("mesh,h\nspot,0.169\n")
    doc = tmp / "doc.md"
    doc.write_text('<!-- figures {"file": "r.csv", "columns": {"H %": ["h"]}} -->\n'
                   "| mesh | H % |\n|---|---|\n| spot | 0.17 |\n| bunny | 0.20 |\n")
    errs = figure_errors(tmp, [doc])
    assert any("no provenance" in e for e in errs), errs
    assert any("0 rows of r.csv" in e for e in errs), errs
    assert not any("shows" in e for e in errs), errs


def test_checker_fails_on_a_broken_link():
    tmp = Path(tempfile.mkdtemp())
    (tmp / "a.md").write_text("# Title\n\n[ok](a.md#title) [gone](b.md) [bad anchor](a.md#nope)\n")
    errs = link_errors(tmp, [tmp / "a.md"])
    assert len(errs) == 2 and "b.md" in errs[0] and "nope" in errs[1], errs
