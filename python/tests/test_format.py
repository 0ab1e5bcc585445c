"""What the files say about themselves (docs/FORMAT.md): units, descriptions
and dimension labels stored in the HDF5 files the real CLI wrote, HDF5
dimension scales attached where the file holds an axis's coordinates, and
the package reading its axes from the file."""

import h5py
import numpy as np


def _walk(f):
    """Every dataset of ``f`` reached by hard links (not the study's
    external links to the variant files)."""
    out = {}

    def visit(group, prefix):
        for name in group:
            link = group.get(name, getlink=True)
            if not isinstance(link, h5py.HardLink):
                continue
            obj = group[name]
            path = f"{prefix}/{name}"
            if isinstance(obj, h5py.Group):
                visit(obj, path)
            else:
                out[path] = obj

    visit(f, "")
    return out


def _check_file(path):
    with h5py.File(path, "r") as f:
        datasets = _walk(f)
        scales = {}
        for p, ds in datasets.items():
            if ds.is_scale:
                scales.setdefault(ds.attrs["NAME"].decode().rstrip("\0"), []).append(p)
        for p, ds in datasets.items():
            assert isinstance(ds.attrs["units"], str), p
            assert ds.attrs["description"].strip(), p
            labels = [d.label for d in ds.dims]
            assert all(labels), (p, labels)
            for i, label in enumerate(labels):
                if label in scales and not ds.is_scale:
                    attached = [s.name for s in ds.dims[i].values()]
                    assert attached, (p, label)
                    assert attached[0] in scales[label], (p, label, attached)
        return {p: (ds.attrs["units"], [d.label for d in ds.dims]) for p, ds in datasets.items()}


def test_result_file_says_units_and_axes(tiny):
    seen = _check_file(tiny.path)
    assert seen["/appearance/brdf_diffuse"] == (
        "sr-1", ["wavelength_nm", "illumination_deg", "viewing_deg"])
    assert seen["/appearance/natural_srgb8"] == ("1", ["viewing_deg", "rgb"])
    assert seen["/geometry/centers_nm"] == ("nm", ["sphere", "xyz"])
    assert seen["/solves/0000/orders_mn"] == ("1", ["order", "mn"])
    assert seen["/config"] == ("", [])
    with h5py.File(tiny.path, "r") as f:
        ds = f["appearance/reflectance"]
        assert ds.dims[0][0].name == "/appearance/wavelengths_nm"
        assert ds.dims[1][0].name == "/appearance/above_deg"
        np.testing.assert_array_equal(ds.dims[0][0][()], [450.0, 600.0])
        assert "κ_inc" in f["solves/0000/orders_mn"].attrs["description"]


def test_package_reads_axes_and_descriptions_from_the_file(tiny):
    ap = tiny.appearance
    # not in the package's own table: the file names the axes
    assert ap["tile_de00_se"].dims == ("viewing_deg", "tile_column")
    assert ap["tile_lab_realisations"].dims == ("realisation", "viewing_deg", "tile_column", "lab")
    assert ap["tile_de00_se"].attrs["units"] == "1"
    assert "ΔE00" in ap["tile_de00_se"].attrs["long_name"]
    # the scale bookkeeping stays out of the attributes
    for v in list(ap.data_vars.values()) + list(ap.coords.values()):
        assert not {"CLASS", "DIMENSION_LIST", "REFERENCE_LIST"} & set(v.attrs), v.name


def test_study_summary_says_units_and_axes(study):
    seen = _check_file(study.path)
    assert seen["/mean_reflectance"] == ("1", ["variant"])
    assert seen["/natural_srgb8"] == ("1", ["variant", "rgb"])
    assert seen["/labels/d"] == ("", ["variant"])
    assert seen["/colour/45_0/lab"] == ("1", ["variant", "lab"])
    with h5py.File(study.path, "r") as f:
        assert f["mean_reflectance"].dims[0][0].name == "/name"
    assert study.table["variant"].attrs["units"] == ""
    assert "CLASS" not in study.table["variant"].attrs
