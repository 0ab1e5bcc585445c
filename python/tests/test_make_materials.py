"""scripts/make_materials.py: the conversion of refractiveindex.info entries
into the library tables of data/materials/, and the tables it wrote.

The conversion rules are checked on entries written here; the tables in the
repository are read back against inksim's table rules and their headers. With
INKSIM_RII_DATABASE set to a refractiveindex.info-database checkout (or git
directory) at the commit data/materials/SOURCE.md names, and PyYAML
installed, the library is regenerated and must equal the committed files
byte for byte.
"""

import importlib.util
import math
import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "data" / "materials"


def load_script():
    spec = importlib.util.spec_from_file_location(
        "make_materials", REPO / "scripts" / "make_materials.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


mm = load_script()


def test_each_dispersion_formula_is_the_documented_one():
    # Values worked by hand from the formulas of the database's
    # "Dispersion formulas" document, wavelength 0.5 um.
    w = 0.5
    # 1 Sellmeier: n^2 - 1 = C1 + C2 w^2 / (w^2 - C3^2)
    assert mm.formula_n(1, [0.5, 1.0, 0.1], w) == pytest.approx(
        math.sqrt(1.5 + 0.25 / (0.25 - 0.01))
    )
    # 2 Sellmeier-2: n^2 - 1 = C1 + C2 w^2 / (w^2 - C3)
    assert mm.formula_n(2, [0.5, 1.0, 0.1], w) == pytest.approx(
        math.sqrt(1.5 + 0.25 / (0.25 - 0.1))
    )
    # 3 polynomial: n^2 = C1 + C2 w^C3
    assert mm.formula_n(3, [2.0, 0.4, -2.0], w) == pytest.approx(math.sqrt(2.0 + 1.6))
    # 4 RefractiveIndex.INFO (rutile, Devore 1951, n_o at 550 nm ~ 2.648)
    devore = [5.913, 0.2441, 0, 0.0803, 1, 0, 0, 0, 1]
    assert mm.formula_n(4, devore, 0.55) == pytest.approx(
        math.sqrt(5.913 + 0.2441 / (0.3025 - 0.0803))
    )
    assert mm.formula_n(4, devore, 0.55) == pytest.approx(2.648, abs=1e-3)
    # 5 Cauchy: n = C1 + C2 w^C3
    assert mm.formula_n(5, [1.5, 0.01, -2.0], w) == pytest.approx(1.54)
    # 6 gases: n - 1 = C1 + C2 / (C3 - w^-2)
    assert mm.formula_n(6, [0.0, 0.01, 10.0], w) == pytest.approx(1 + 0.01 / 6.0)
    # 7 Herzberger: n = C1 + C2 L + C3 L^2 + C4 w^2 ..., L = 1/(w^2 - 0.028)
    L = 1 / (0.25 - 0.028)
    assert mm.formula_n(7, [1.5, 0.01, 0.001, 0.002], w) == pytest.approx(
        1.5 + 0.01 * L + 0.001 * L * L + 0.002 * 0.25
    )
    # 8 retro: (n^2 - 1)/(n^2 + 2) = C1 + C2 w^2/(w^2 - C3) + C4 w^2
    a = 0.2 + 0.1 * 0.25 / (0.25 - 0.01)
    assert mm.formula_n(8, [0.2, 0.1, 0.01, 0.0], w) == pytest.approx(
        math.sqrt((1 + 2 * a) / (1 - a))
    )
    # 9 exotic: n^2 = C1 + C2/(w^2 - C3) + C4 (w - C5)/((w - C5)^2 + C6)
    assert mm.formula_n(9, [2.0, 0.1, 0.05, 0.01, 0.3, 0.02], w) == pytest.approx(
        math.sqrt(2.0 + 0.1 / 0.2 + 0.01 * 0.2 / (0.04 + 0.02))
    )
    with pytest.raises(mm.ConversionError):
        mm.formula_n(10, [1.0], w)


def test_references_become_one_line_of_plain_text():
    html = (
        "J. R. Devore.\n    Refractive indices of rutile and sphalerite.\n"
        '    <a href="https://doi.org/10.1364/JOSA.41.000416"><i>J. Opt. Soc. Am.</i> '
        "<b>41</b>, 416-419 (1951)</a><br>TiO<sub>2</sub> &amp; more"
    )
    assert mm.plain(html) == (
        "J. R. Devore. Refractive indices of rutile and sphalerite. J. Opt. Soc. Am. "
        "41, 416-419 (1951) (https://doi.org/10.1364/JOSA.41.000416); TiO2 & more"
    )
    assert mm.plain("**Film** [paper](https://x.org/a)") == "Film paper (https://x.org/a)"


def test_wavelengths_convert_exactly():
    assert mm.um_to_nm("0.2100") == "210"
    assert mm.um_to_nm("0.28054") == "280.54"
    assert mm.um_to_nm("1.0332") == "1033.2"
    assert mm.um_to_nm("5.5556e-1") == "555.56"


def test_entries_convert_by_their_form_within_the_window():
    rows = "0.2 1.0 0.5\n0.3 1.1 0.4\n0.5 1.2 0.3\n1.1 1.3 0.2\n1.2 1.4 0.1\n"
    got, desc = mm.convert({"DATA": [{"type": "tabulated nk", "data": rows}]}, "t")
    assert got == [("300", "1.1", "0.4"), ("500", "1.2", "0.3"), ("1100", "1.3", "0.2")]
    assert "copied" in desc

    got, desc = mm.convert(
        {"DATA": [{"type": "tabulated n", "data": "0.4 1.5\n0.6 1.6\n"}]}, "t"
    )
    assert got == [("400", "1.5", "0"), ("600", "1.6", "0")]
    assert "k = 0" in desc

    got, _ = mm.convert(
        {
            "DATA": [
                {"type": "tabulated n", "data": "0.4 1.5\n0.5 1.55\n0.6 1.6\n0.7 1.7\n"},
                {"type": "tabulated k", "data": "0.45 0.1\n0.65 0.3\n"},
            ]
        },
        "t",
    )
    # n's rows inside k's range, k interpolated at them.
    assert got == [("500", "1.55", "0.15"), ("600", "1.6", "0.25")]

    # A formula is evaluated on the 5 nm grid inside its valid range only.
    got, desc = mm.convert(
        {
            "DATA": [
                {
                    "type": "formula 4",
                    "wavelength_range": "0.43 1.53",
                    "coefficients": "5.913 0.2441 0 0.0803 1 0 0 0 1",
                }
            ]
        },
        "t",
    )
    assert got[0][0] == "430" and got[-1][0] == "1100" and len(got) == 135
    assert got[24] == ("550", "2.647935", "0")
    assert "valid 430-1530 nm" in desc

    with pytest.raises(mm.ConversionError, match="not a form"):
        mm.convert({"DATA": [{"type": "tabulated n2", "data": "1 2\n"}]}, "t")


def test_values_beyond_the_limits_stop_the_script():
    mm.check_rows([("400", "1.5", "0"), ("500", "10", "10")], "t")
    with pytest.raises(mm.ConversionError, match="k = 10.9"):
        mm.check_rows([("400", "1.3", "9.9"), ("1127", "1.3", "10.9")], "al")
    with pytest.raises(mm.ConversionError, match="not after"):
        mm.check_rows([("500", "1.5", "0"), ("500", "1.5", "0")], "t")
    with pytest.raises(mm.ConversionError, match="outside \\(0, 10\\]"):
        mm.check_rows([("400", "0", "0"), ("500", "1", "0")], "t")


def read_table(path):
    header, rows, columns = {}, [], None
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("# "):
            key, _, value = line[2:].partition(": ")
            header[key] = value
        elif columns is None:
            columns = line
        else:
            rows.append(tuple(float(x) for x in line.split(",")))
    return header, columns, rows


def test_the_committed_tables_follow_the_rules_and_state_their_source():
    files = sorted(DATA.glob("*.csv"))
    assert len(files) == 13  # 9 materials, 4 of them crystals (o and e)
    commit = None
    for path in files:
        header, columns, rows = read_table(path)
        assert columns == "wavelength_nm,n,k", path.name
        wl = [r[0] for r in rows]
        assert all(a < b for a, b in zip(wl, wl[1:])), path.name
        assert all(0 < n <= 10 and 0 <= k <= 10 for _, n, k in rows), path.name
        lo, hi = header["range"].removesuffix(" nm").split("-")
        assert (float(lo), float(hi)) == (wl[0], wl[-1]), path.name
        start = 430 if path.name.startswith("rutile") else 380
        assert wl[0] <= start and wl[-1] >= 780, path.name
        for key in ("material", "page", "reference", "licence", "source"):
            assert header.get(key), f"{path.name}: {key}"
        assert header["licence"].startswith("CC0 1.0")
        assert "generated by scripts/make_materials.py; do not edit" in header
        this = header["source"].split("commit ")[1].split(",")[0]
        assert commit in (None, this), path.name
        commit = this
    assert f"`{commit}`" in (DATA / "SOURCE.md").read_text(encoding="utf-8")


def test_regenerating_gives_the_committed_files(tmp_path):
    database = os.environ.get("INKSIM_RII_DATABASE")
    if not database:
        pytest.skip("INKSIM_RII_DATABASE (a refractiveindex.info-database checkout) not set")
    pytest.importorskip("yaml")
    assert mm.main([database, "--out", str(tmp_path)]) == 0
    written = sorted(p.name for p in tmp_path.iterdir())
    committed = sorted(p.name for p in DATA.iterdir())
    assert written == committed
    for name in written:
        assert (tmp_path / name).read_bytes() == (DATA / name).read_bytes(), name
