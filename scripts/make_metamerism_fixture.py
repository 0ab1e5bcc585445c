#!/usr/bin/env python3
"""Generate the test sources and the reference values of the special metamerism index, computed
ONCE with an independent library (colour-science, PyPI package `colour-science`, version recorded
in the files). Run from the crate root:

    pip install colour-science==0.4.7
    python3 scripts/make_metamerism_fixture.py

It writes:
- data/cie/cie_fl11_5nm.csv and data/cie/cie_led_b3_5nm.csv: CIE illuminants FL11 (tri-band
  fluorescent, CIE 015:2004 Table T.8.2) and LED-B3 (phosphor-converted white LED, CIE 015:2018
  Table 11.4), 380-780 nm at 5 nm, verbatim from colour.SDS_ILLUMINANTS.
- tests/fixtures/metamerism_spectra.csv: pairs of reflectance spectra on the 1 nm grid 360-830 nm.
- tests/fixtures/metamerism_expected.csv: per pair, per test source and observer, the CIEDE2000
  difference under the test source before and after the multiplicative parameric correction in
  XYZ under the reference illuminant (D50), i.e. the special metamerism index for a change of
  illuminant (ISO 18314-4; CIE 015:2004 section 9.2 for the correction).

Everything is computed by colour-science: its CIE 1931 2 degree and CIE 1964 10 degree colour
matching functions, sd_to_XYZ(method="Integration") on the 1 nm grid, XYZ_to_Lab relative to the
perfect reflecting diffuser, delta_E(method="CIE 2000"). The 5 nm sources are put on the 1 nm grid
by linear interpolation and held at their 380 / 780 nm values beyond (numpy.interp), the
convention inksim documents for its tabulated illuminants; illuminant A is colour-science's
sd_CIE_standard_illuminant_A (the CIE formula) on the 1 nm grid and D50 is colour-science's CIE table, also linearly interpolated.
"""

import pathlib

import colour
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCES = {
    "FL11": (ROOT / "data" / "cie" / "cie_fl11_5nm.csv",
             "CIE illuminant FL11 (F11, tri-band fluorescent, 4000 K) relative spectral power, "
             "380-780 nm at 5 nm,\n# CIE 015:2004 Table T.8.2"),
    "LED-B3": (ROOT / "data" / "cie" / "cie_led_b3_5nm.csv",
               "CIE illuminant LED-B3 (phosphor-converted blue LED, 4103 K) relative spectral "
               "power, 380-780 nm at 5 nm,\n# CIE 015:2018 Table 11.4"),
}
OUT_SPECTRA = ROOT / "tests" / "fixtures" / "metamerism_spectra.csv"
OUT_EXPECTED = ROOT / "tests" / "fixtures" / "metamerism_expected.csv"
CMFS = {
    2: "CIE 1931 2 Degree Standard Observer",
    10: "CIE 1964 10 Degree Standard Observer",
}


def gauss(wl, centre, sigma):
    return np.exp(-0.5 * ((wl - centre) / sigma) ** 2)


def on_grid(sd, wl):
    """A tabulated source linearly interpolated onto wl, held at its ends."""
    return np.interp(wl, sd.wavelengths, sd.values)


def pairs(wl):
    """(standard, trial) reflectance pairs: a grey against a metameric-looking grey made of
    bands, a red against a slightly different red, a spectral match."""
    grey = np.full_like(wl, 0.4)
    bands = 0.18 + 0.30 * gauss(wl, 450.0, 22.0) + 0.32 * gauss(wl, 545.0, 25.0) \
        + 0.36 * gauss(wl, 610.0, 25.0)
    red = 0.05 + 0.75 / (1.0 + np.exp(-(wl - 600.0) / 12.0))
    red2 = 0.07 + 0.70 / (1.0 + np.exp(-(wl - 596.0) / 18.0)) + 0.04 * gauss(wl, 450.0, 30.0)
    blue = 0.08 + 0.55 * gauss(wl, 460.0, 40.0)
    return {
        "grey_vs_bands": (grey, bands),
        "red_vs_red2": (red, red2),
        "blue_vs_blue": (blue, blue.copy()),
    }


def main():
    header = f"# exported verbatim from colour-science {colour.__version__} " \
             "(PyPI; colour.SDS_ILLUMINANTS) by scripts/make_metamerism_fixture.py\n"
    for name, (path, what) in SOURCES.items():
        sd = colour.SDS_ILLUMINANTS[name]
        with open(path, "w") as f:
            f.write(f"# {what}\n{header}wavelength_nm,S\n")
            for w, v in zip(sd.wavelengths, sd.values):
                f.write(f"{w:g},{v:.6g}\n")

    wl = np.arange(360.0, 831.0, 1.0)
    ps = pairs(wl)
    with open(OUT_SPECTRA, "w") as f:
        f.write(f"# reflectance pairs (standard, trial) for the metamerism index; "
                f"scripts/make_metamerism_fixture.py, colour-science {colour.__version__}\n")
        names = [f"{p}_{k}" for p in ps for k in ("standard", "trial")]
        f.write("wavelength_nm," + ",".join(names) + "\n")
        for i, w in enumerate(wl):
            vals = [ps[p][k][i] for p in ps for k in (0, 1)]
            f.write(f"{w:g}," + ",".join(f"{v:.10f}" for v in vals) + "\n")

    rows = []
    for deg, cmf_name in CMFS.items():
        cmfs = colour.MSDS_CMFS[cmf_name].copy().align(colour.SpectralShape(360, 830, 1))
        assert np.allclose(cmfs.wavelengths, wl)

        def source(name):
            if name == "A":
                return colour.colorimetry.sd_CIE_standard_illuminant_A(colour.SpectralShape(360, 830, 1))
            sd = colour.SDS_ILLUMINANTS[name]
            return colour.SpectralDistribution(dict(zip(wl, on_grid(sd, wl))))

        def xyz(refl, ill):
            sd = colour.SpectralDistribution(dict(zip(wl, refl)))
            return colour.sd_to_XYZ(sd, cmfs, ill, method="Integration")

        def lab(x, white):
            return colour.XYZ_to_Lab(x / 100.0, colour.XYZ_to_xy(white / 100.0))

        ref = source("D50")
        ref_white = xyz(np.ones_like(wl), ref)
        for test in ("A", "FL11", "LED-B3"):
            ill = source(test)
            white = xyz(np.ones_like(wl), ill)
            for p, (std, trial) in ps.items():
                s_r, t_r = xyz(std, ref), xyz(trial, ref)
                s_t, t_t = xyz(std, ill), xyz(trial, ill)
                corrected = t_t * s_r / t_r
                de_ref = colour.delta_E(lab(s_r, ref_white), lab(t_r, ref_white), method="CIE 2000")
                de_raw = colour.delta_E(lab(s_t, white), lab(t_t, white), method="CIE 2000")
                mi = colour.delta_E(lab(s_t, white), lab(corrected, white), method="CIE 2000")
                rows.append((p, deg, test, de_ref, de_raw, mi))
    with open(OUT_EXPECTED, "w") as f:
        f.write(f"# special metamerism index, reference D50, by colour-science {colour.__version__} "
                "(scripts/make_metamerism_fixture.py)\n")
        f.write("pair,observer_deg,test_source,de00_reference,de00_test_uncorrected,"
                "metamerism_index\n")
        for r in rows:
            f.write(f"{r[0]},{r[1]},{r[2]},{r[3]:.8f},{r[4]:.8f},{r[5]:.8f}\n")


if __name__ == "__main__":
    main()
