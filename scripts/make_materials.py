#!/usr/bin/env python3
"""Write the material library data/materials/ from the refractiveindex.info database.

The library holds optical constants from published measurements, converted
from the refractiveindex.info database (M. N. Polyanskiy, Sci. Data 11, 94
(2024); https://github.com/polyanskiy/refractiveindex.info-database), which is
in the public domain (CC0 1.0 Universal). Nothing in data/materials/ is typed
by hand: this script reads the chosen database entries (MATERIALS below) and
writes one table per entry, in inksim's table format:

    # key: value          header comments: material, page, reference, ...
    wavelength_nm,n,k
    430,2.869837,0        strictly increasing wavelengths, 0 < n <= 10, 0 <= k <= 10

A uniaxial crystal is one library name with two tables, <name>-o.csv
(ordinary ray) and <name>-e.csv (extraordinary ray); any other material is
<name>.csv. The script also writes data/materials/SOURCE.md (source, licence,
the database commit, the entries, how to regenerate).

Entries are converted as follows; wavelengths are kept within WINDOW_NM
(the visible with a margin on each side), and the header's `range` is what
the table covers:

- `tabulated nk`: the entry's rows in the window, numbers copied verbatim
  (wavelengths converted from um to nm exactly, in decimal).
- `tabulated n` (with no k): k = 0, said in the header.
- `tabulated n` and `tabulated k`: n's rows in the window and within k's
  range, k interpolated linearly at n's wavelengths.
- `formula 1` .. `formula 9`: n evaluated every FORMULA_STEP_NM on the grid
  of multiples of the step inside both the window and the formula's stated
  valid range (never outside it); k = 0, or a following `tabulated k`
  interpolated as above.

Any value outside inksim's limits (0 < n <= 10, 0 <= k <= 10) stops the
script with the entry and the row: nothing is dropped silently.

Usage (python3 with PyYAML):

    git clone https://github.com/polyanskiy/refractiveindex.info-database rii
    git -C rii checkout <commit named in data/materials/SOURCE.md>
    python3 scripts/make_materials.py rii

DATABASE may be a checkout (the folder holding database/) or a bare git
directory (read with `git show`). `--out DIR` writes elsewhere (the tests
regenerate into a temporary folder and compare).
"""

import argparse
import html
import math
import os
import re
import subprocess
import sys
import urllib.parse
from decimal import Decimal

WINDOW_NM = (300, 1100)
FORMULA_STEP_NM = 5
N_DIGITS = 6
MAX_INDEX = 10.0
LICENCE = "CC0 1.0 Universal (public domain dedication), refractiveindex.info database"
REPOSITORY = "https://github.com/polyanskiy/refractiveindex.info-database"
DATABASE_CITATION = (
    "M. N. Polyanskiy, Refractiveindex.info database of optical constants, "
    "Sci. Data 11, 94 (2024), https://doi.org/10.1038/s41597-023-02898-2"
)

# Library name -> (what it is, ordinary/isotropic entry, extraordinary entry
# or None), entries as paths under database/data/. Choices (all cover at least
# 400-700 nm except rutile, see its note):
MATERIALS = [
    # Rutile: the crystal entries are Devore 1951 (formula, 430-1530 nm) and
    # Bond 1965 (tabulated n, 450-2400 nm); none starts below 430 nm, where
    # rutile's absorption edge (~410 nm) begins. Devore covers more.
    ("rutile", "rutile TiO2 (titanium white)",
     "main/TiO2/nk/Devore-o.yml", "main/TiO2/nk/Devore-e.yml"),
    # Anatase: no crystal (o/e) entry in the database; Jolivet 2023 is a
    # polycrystalline film (207-827 nm). Bodurov 2016 (nanoparticles) covers
    # only 405-635 nm.
    ("anatase", "anatase TiO2, polycrystalline film",
     "main/TiO2/nk/Jolivet-anatase.yml", None),
    ("hematite", "alpha-Fe2O3 hematite (red iron oxide)",
     "main/Fe2O3/nk/Querry-o.yml", "main/Fe2O3/nk/Querry-e.yml"),
    # CdS: Ninomiya 1995 (wurtzite crystal, o/e, 218-1033 nm); Bieniewski's
    # formula starts at 510 nm.
    ("cds", "CdS greenockite (cadmium yellow)",
     "main/CdS/nk/Ninomiya-o.yml", "main/CdS/nk/Ninomiya-e.yml"),
    # ZnO: the crystal entries (Bond 1965, o/e formula) start at 450 nm;
    # Aguilar 2019 (film, 300-3200 nm) covers the visible.
    ("zno", "ZnO (zinc white), film",
     "main/ZnO/nk/Aguilar.yml", None),
    ("calcite", "CaCO3 calcite (chalk, whiting)",
     "main/CaCO3/nk/Ghosh-o.yml", "main/CaCO3/nk/Ghosh-e.yml"),
    # Soot: Querry's diesel soot (260 nm - 55.6 um); Dalzell's acetylene and
    # propane soots start at 436 nm.
    ("soot", "diesel soot (a carbon black)",
     "other/soots/diesel soot/nk/Querry-NMSU.yml", None),
    ("amorphous-carbon", "amorphous carbon, arc-evaporated film",
     "main/C/nk/Arakawa.yml", None),
    # Aluminium: Rakic 1995; k <= 10 up to 1033 nm (k = 11 at 1127 nm,
    # outside the window).
    ("aluminium", "Al (aluminium), evaporated film",
     "main/Al/nk/Rakic.yml", None),
]


class ConversionError(Exception):
    """An entry that cannot become an inksim table (named in the message)."""


# ---------------------------------------------------------------- database


class Database:
    """The database as a checkout or a bare git directory; `read(path)`
    returns the text of database/<path>."""

    def __init__(self, root):
        self.root = root
        if os.path.isfile(os.path.join(root, "database", "catalog-nk.yml")):
            self.git_dir = None
            self.commit = self._git(["-C", root, "rev-parse", "HEAD"], required=False)
        else:
            self.git_dir = root
            self.commit = self._git(["--git-dir", root, "rev-parse", "HEAD"], required=True)
        self._catalog = None

    @staticmethod
    def _git(args, required):
        try:
            out = subprocess.run(["git"] + args, check=True, capture_output=True, text=True)
            return out.stdout.strip()
        except (OSError, subprocess.CalledProcessError) as e:
            if required:
                raise ConversionError(f"not a database checkout or git directory: {e}")
            return None

    def read(self, path):
        if self.git_dir is None:
            with open(os.path.join(self.root, "database", path), encoding="utf-8") as f:
                return f.read()
        return self._git(
            ["--git-dir", self.git_dir, "show", f"{self.commit}:database/{path}"],
            required=True,
        )

    def load(self, path):
        import yaml  # PyYAML, needed only to read the database

        return yaml.safe_load(self.read(path))

    def page(self, data_path):
        """(shelf, book, page) of the first catalog page holding data_path."""
        if self._catalog is None:
            self._catalog = self.load("catalog-nk.yml")
        for shelf in self._catalog:
            if "SHELF" not in shelf:
                continue
            for book in shelf.get("content", []):
                if "BOOK" not in book:
                    continue
                for page in book.get("content", []):
                    if page.get("data") == data_path:
                        return shelf["SHELF"], book["BOOK"], page["PAGE"]
        raise ConversionError(f"{data_path}: not on any page of catalog-nk.yml")


# ---------------------------------------------------------------- text


def plain(text):
    """One line of plain text from a database REFERENCES/COMMENTS field:
    links become `text (url)` (HTML or Markdown), other tags go, entities are
    decoded, whitespace is collapsed."""
    if not text:
        return ""
    text = str(text)
    text = re.sub(
        r'<a\s+href\s*=\s*"?\\?([^">\s]+)"?[^>]*>(.*?)</a>',
        lambda m: f"{m.group(2)} ({m.group(1)})",
        text,
        flags=re.S | re.I,
    )
    text = re.sub(r"\[([^\]]+)\]\((https?://[^)\s]+)\)", r"\1 (\2)", text)
    text = re.sub(r"<br\s*/?>|</br>", "; ", text, flags=re.I)
    text = re.sub(r"<[^>]+>", "", text)
    text = html.unescape(text)
    # Markdown emphasis, and the stray escapes and quotes of a few entries.
    text = text.replace("**", "").replace("\\", "").replace('""', "")
    text = re.sub(r"\s*;\s*(;\s*)+", "; ", text)
    text = re.sub(r"\s+", " ", text).strip()
    return text.strip("; ")


def decimal_text(d):
    """A Decimal as plain positional text without trailing zeros."""
    s = format(d.normalize(), "f")
    return "0" if s in ("-0", "") else s


def um_to_nm(text):
    """A wavelength in um (database text) as nm text, exact in decimal."""
    return decimal_text(Decimal(text) * 1000)


# ---------------------------------------------------------------- formulas


def formula_n(kind, c, wl):
    """n at wavelength wl (um) by the database's dispersion formula `kind`
    (1..9) with coefficients c (missing ones are 0), as defined in the
    database's doc/Dispersion formulas.pdf."""
    c = list(c) + [0.0] * (17 - len(c))
    C = [None] + c  # C[1] .. C[17], as in the database's documentation
    w2 = wl * wl
    if kind == 1:  # Sellmeier
        n2 = 1 + C[1] + sum(C[i] * w2 / (w2 - C[i + 1] ** 2) for i in range(2, 17, 2))
    elif kind == 2:  # Sellmeier-2
        n2 = 1 + C[1] + sum(C[i] * w2 / (w2 - C[i + 1]) for i in range(2, 17, 2))
    elif kind == 3:  # polynomial
        n2 = C[1] + sum(C[i] * wl ** C[i + 1] for i in range(2, 17, 2))
    elif kind == 4:  # RefractiveIndex.INFO
        n2 = (
            C[1]
            + C[2] * wl ** C[3] / (w2 - C[4] ** C[5])
            + C[6] * wl ** C[7] / (w2 - C[8] ** C[9])
            + sum(C[i] * wl ** C[i + 1] for i in range(10, 17, 2))
        )
    elif kind == 5:  # Cauchy
        return C[1] + sum(C[i] * wl ** C[i + 1] for i in range(2, 12, 2))
    elif kind == 6:  # gases
        return 1 + C[1] + sum(C[i] / (C[i + 1] - wl ** -2) for i in range(2, 12, 2))
    elif kind == 7:  # Herzberger
        L = 1 / (w2 - 0.028)
        return C[1] + C[2] * L + C[3] * L * L + C[4] * w2 + C[5] * w2**2 + C[6] * w2**3
    elif kind == 8:  # Retro
        a = C[1] + C[2] * w2 / (w2 - C[3]) + C[4] * w2
        n2 = (1 + 2 * a) / (1 - a)
    elif kind == 9:  # Exotic
        n2 = C[1] + C[2] / (w2 - C[3]) + C[4] * (wl - C[5]) / ((wl - C[5]) ** 2 + C[6])
    else:
        raise ConversionError(f"formula {kind}: unknown (the database defines 1..9)")
    if not n2 > 0:
        raise ConversionError(f"formula {kind}: n^2 = {n2} <= 0 at {wl} um")
    return math.sqrt(n2)


def grid_nm(lo_nm, hi_nm, step):
    """Multiples of `step` (nm) in [lo_nm, hi_nm]."""
    first = math.ceil(lo_nm / step - 1e-9)
    last = math.floor(hi_nm / step + 1e-9)
    return [i * step for i in range(first, last + 1)]


def interpolate(rows, wl):
    """Linear interpolation of (wavelength, value) rows at wl (inside them)."""
    for (w0, v0), (w1, v1) in zip(rows, rows[1:]):
        if w0 <= wl <= w1:
            return v0 + (v1 - v0) * (wl - w0) / (w1 - w0)
    raise ConversionError(f"{wl} outside the tabulated k")


# ---------------------------------------------------------------- conversion


def tabulated(block):
    """The text rows of a tabulated block, as lists of number strings."""
    rows = [line.split() for line in str(block["data"]).strip().splitlines() if line.strip()]
    return sorted(rows, key=lambda r: float(r[0]))


def in_window(wl_nm):
    return WINDOW_NM[0] <= wl_nm <= WINDOW_NM[1]


def convert(entry, where):
    """(rows as (wavelength text, n text, k text), description of the data)
    of a parsed database entry; `where` names it in errors."""
    blocks = entry.get("DATA") or []
    kinds = [b["type"] for b in blocks]
    lo, hi = WINDOW_NM
    if kinds == ["tabulated nk"]:
        rows = [(um_to_nm(w), n, k) for w, n, k in tabulated(blocks[0])]
        rows = [r for r in rows if in_window(float(r[0]))]
        return rows, "tabulated n, k (the entry's rows, copied)"
    if kinds == ["tabulated n"]:
        rows = [(um_to_nm(w), n, "0") for w, n in tabulated(blocks[0])]
        rows = [r for r in rows if in_window(float(r[0]))]
        return rows, "tabulated n (the entry's rows, copied); k = 0: the entry gives no k"
    k_rows = None
    if len(blocks) == 2 and kinds[1] == "tabulated k":
        k_rows = [(float(w) * 1000, float(k)) for w, k in tabulated(blocks[1])]

    def k_at(wl_nm):
        return "0" if k_rows is None else f"{interpolate(k_rows, wl_nm):.{N_DIGITS}g}"

    def k_span(a, b):
        if k_rows is None:
            return a, b
        return max(a, k_rows[0][0]), min(b, k_rows[-1][0])

    k_note = (
        "k = 0: the entry gives no k"
        if k_rows is None
        else "k interpolated linearly in the entry's tabulated k"
    )
    if kinds == ["tabulated n", "tabulated k"]:
        a, b = k_span(lo, hi)
        rows = [
            (um_to_nm(w), n, k_at(float(w) * 1000))
            for w, n in tabulated(blocks[0])
            if a <= float(w) * 1000 <= b
        ]
        return rows, f"tabulated n (the entry's rows, copied); {k_note}"
    m = re.fullmatch(r"formula (\d+)", kinds[0]) if kinds else None
    if m and (len(blocks) == 1 or k_rows is not None):
        kind = int(m.group(1))
        b = blocks[0]
        v_lo, v_hi = (float(x) * 1000 for x in str(b["wavelength_range"]).split())
        coefficients = [float(x) for x in str(b["coefficients"]).split()]
        a, z = k_span(max(lo, v_lo), min(hi, v_hi))
        rows = []
        for wl in grid_nm(a, z, FORMULA_STEP_NM):
            n = formula_n(kind, coefficients, wl / 1000.0)
            rows.append((str(wl), f"{n:.{N_DIGITS}f}", k_at(wl)))
        desc = (
            f"formula {kind} (valid {v_lo:g}-{v_hi:g} nm) evaluated every "
            f"{FORMULA_STEP_NM} nm; {k_note}"
        )
        return rows, desc
    raise ConversionError(f"{where}: data {kinds} is not a form this script converts")


def check_rows(rows, where):
    """inksim's table rules, row by row."""
    if len(rows) < 2:
        raise ConversionError(f"{where}: {len(rows)} rows in {WINDOW_NM} nm, need 2")
    prev = None
    for w, n, k in rows:
        wl, nn, kk = float(w), float(n), float(k)
        if prev is not None and not wl > prev:
            raise ConversionError(f"{where}: wavelength {w} nm not after {prev} nm")
        if not 0 < nn <= MAX_INDEX:
            raise ConversionError(f"{where}: n = {n} at {w} nm outside (0, {MAX_INDEX:g}]")
        if not 0 <= kk <= MAX_INDEX:
            raise ConversionError(f"{where}: k = {k} at {w} nm outside [0, {MAX_INDEX:g}]")
        prev = wl


def ray_of(entry, suffix):
    direction = (entry.get("CONDITIONS") or {}).get("direction")
    if suffix and direction != suffix:
        raise ConversionError(f"entry for ray `{suffix}` has direction {direction!r}")
    return {"o": ", ordinary ray (o)", "e": ", extraordinary ray (e)"}.get(suffix, "")


def table_text(db, name, title, data_path, suffix):
    """(file name, text, summary) of one library table."""
    entry = db.load(f"data/{data_path}")
    shelf, book, page = db.page(data_path)
    where = f"{data_path} ({name})"
    rows, data_desc = convert(entry, where)
    check_rows(rows, where)
    url = "https://refractiveindex.info/?" + urllib.parse.urlencode(
        {"shelf": shelf, "book": book, "page": page}
    )
    range_text = f"{rows[0][0]}-{rows[-1][0]} nm"
    header = [
        f"inksim material library: {name}{ray_of(entry, suffix)}",
        f"material: {title}{ray_of(entry, suffix)}",
        f"page: {shelf}/{book}/{page} ({url})",
        f"reference: {plain(entry.get('REFERENCES'))}",
        f"comments: {plain(entry.get('COMMENTS')) or '-'}",
        f"data: {data_desc}; kept within {WINDOW_NM[0]}-{WINDOW_NM[1]} nm",
        f"range: {range_text}",
        f"licence: {LICENCE}",
        f"source: {REPOSITORY}, commit {db.commit or 'unknown'}, file database/data/{data_path}",
        "generated by scripts/make_materials.py; do not edit",
    ]
    lines = [f"# {h}" for h in header] + ["wavelength_nm,n,k"]
    lines += [f"{w},{n},{k}" for w, n, k in rows]
    file_name = f"{name}-{suffix}.csv" if suffix else f"{name}.csv"
    summary = (file_name, f"{shelf}/{book}/{page}", range_text, plain(entry.get("REFERENCES")))
    return file_name, "\n".join(lines) + "\n", summary


def source_md(db, summaries):
    rows = "\n".join(
        f"| `{f}` | `{p}` | {r} | {ref} |" for f, p, r, ref in summaries
    )
    return f"""# Material library: source

The tables here are optical constants from published measurements, converted
from the **refractiveindex.info database** ({REPOSITORY}) by
`scripts/make_materials.py`; they are generated, not edited.

- Licence: the database is in the public domain: copyright and related rights
  were waived through the CC0 1.0 Universal Public Domain Dedication
  (https://creativecommons.org/publicdomain/zero/1.0/). Each table's header
  repeats it.
- Database commit: `{db.commit or 'unknown'}`
- Database citation: {DATABASE_CITATION}. Cite the original publication of a
  table too (its `reference` line).
- Conversion: each entry's rows within {WINDOW_NM[0]}-{WINDOW_NM[1]} nm,
  numbers copied (wavelengths um -> nm); dispersion formulas evaluated every
  {FORMULA_STEP_NM} nm inside their stated valid range; see the script's
  docstring. Each table's header gives the material, the database page
  (shelf/book/page), the reference, the data form, the wavelength range
  covered, the licence and the source file.
- A uniaxial crystal is one library name with `<name>-o.csv` (ordinary ray)
  and `<name>-e.csv` (extraordinary ray).

To regenerate:

```sh
git clone {REPOSITORY} rii
git -C rii checkout {db.commit or '<commit>'}
python3 scripts/make_materials.py rii      # needs PyYAML
```

`python/tests/test_make_materials.py` checks the conversion rules and these
tables; with `INKSIM_RII_DATABASE=rii` (and PyYAML) it also regenerates the
library and compares it with these files byte for byte.

| file | database page | range | reference |
|---|---|---|---|
{rows}
"""


def generate(db):
    """{file name: text} of the whole library, SOURCE.md included."""
    files, summaries = {}, []
    for name, title, ordinary, extraordinary in MATERIALS:
        if extraordinary is None:
            parts = [(ordinary, None)]
        else:
            parts = [(ordinary, "o"), (extraordinary, "e")]
        for data_path, suffix in parts:
            file_name, text, summary = table_text(db, name, title, data_path, suffix)
            files[file_name] = text
            summaries.append(summary)
    files["SOURCE.md"] = source_md(db, summaries)
    return files


def main(argv=None):
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("database", help="refractiveindex.info-database checkout or git directory")
    parser.add_argument(
        "--out",
        default=os.path.join(here, "..", "data", "materials"),
        help="folder to write (default: data/materials)",
    )
    args = parser.parse_args(argv)
    try:
        files = generate(Database(args.database))
    except ConversionError as e:
        print(f"make_materials: {e}", file=sys.stderr)
        return 1
    os.makedirs(args.out, exist_ok=True)
    stale = {
        f for f in os.listdir(args.out) if f.endswith(".csv") and f not in files
    }
    for f in sorted(stale):
        os.remove(os.path.join(args.out, f))
    for file_name, text in files.items():
        with open(os.path.join(args.out, file_name), "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
    print(f"wrote {len(files)} files to {os.path.normpath(args.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
