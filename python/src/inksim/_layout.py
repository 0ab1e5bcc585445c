"""The result-file layout as Python sees it: dimensions and units of every
array, in one table.

This mirrors the layout documented in docs/FORMAT.md (result files, format
version 1, and a study's ``summary.h5``). HDF5 names stay as they are; the
dimension names are the axes that document states:

=====================  ====================================================
dimension              meaning (Rust docs' letter)
=====================  ====================================================
``wavelength_nm``      vacuum wavelengths of ``/appearance`` (L)
``above_deg``          polar angles solved from above (A)
``illumination_deg``   illumination polar angles of the BRDF (I)
``viewing_deg``        viewing polar angles (V)
``below_deg``          quadrature nodes solved from below (Q)
``sy``, ``sx``         angular table nodes, ``s = sin θ (cos φ, sin φ)`` (N × N)
``tile_column``        tile cells: 0 the white-sky strip, then one per illumination
``solve``              one per ``/solves/NNNN`` group, in solve order
``order``              the propagating orders of all solves, one after another
``sphere``             spheres of the particle set (N)
``particle``           particles (grains; a grain may be several spheres) (P)
``species``            pigment species (S)
``realisation``        independent random fragments (R)
``xyz``, ``lab``, ``rgb``  components: x, y, z / L*, a*, b* / R, G, B
``tristimulus``, ``lch``  components: X, Y, Z / L*, C*ab, h_ab (measured colours)
``z_edge``, ``z``, ``r``  z bin edges and bins of the volume profile, distances of g(r)
``cluster``            clusters of touching grains, largest first
``byte``               bytes of an encoded file (PNG)
``variant``            variants of a study, in expansion order (``summary.h5``)
=====================  ====================================================

Units use UDUNITS-style spellings: ``nm``, ``nm3`` (nm³), ``deg``, ``1``
(dimensionless: efficiencies, fractions), ``sr-1`` (per steradian), ``s``.
What the file says takes precedence over this table: inksim stores a
``units`` and a ``description`` attribute on every dataset and labels its
dimensions (HDF5 dimension labels, with the coordinates attached as
dimension scales), under the same dimension names as here. The table fills
in for files written before inksim stored them, and names the attributes.
"""

from __future__ import annotations

from typing import Dict, Optional, Tuple

# path inside the file -> (dims, units, long name).
# ``*`` stands for one solve group (``solves/0000`` ...); names ending in
# ``@attr`` are HDF5 attributes.
LAYOUT: Dict[str, Tuple[Tuple[str, ...], Optional[str], str]] = {
    # root attributes
    "@format_version": ((), None, "result file format version"),
    "@inksim_version": ((), None, "inksim version that wrote the file"),
    "@config_path": ((), None, "scene file the run read"),
    "@input_hash": ((), None, "SHA-256 of the scene text and its pigment tables"),
    "@seed": ((), None, "scene seed"),
    "@created_unix_s": ((), "s", "creation time, seconds since 1970-01-01 UTC"),
    "@grid": (("xyz",), None, "raster grid nx, ny, nz"),
    "@size_nm": (("xyz",), "nm", "fragment size Lx, Ly and layer thickness H"),
    # geometry
    "geometry/centers_nm": (("sphere", "xyz"), "nm", "sphere centre"),
    "geometry/radii_nm": (("sphere",), "nm", "sphere radius"),
    "geometry/particle_of_sphere": (("sphere",), None, "particle the sphere belongs to"),
    "geometry/species_of_particle": (("particle",), None, "species index of the particle"),
    "geometry/species_names": (("species",), None, "species name"),
    "geometry/target_fraction": (("species",), "1", "target volume fraction"),
    "geometry/achieved_fraction": (("species",), "1", "achieved volume fraction"),
    "geometry/raster_fraction": (("species",), "1", "volume fraction on the raster"),
    "geometry@min_gap_nm": ((), "nm", "smallest surface gap between grains"),
    "geometry/statistics/count": (("species",), "1", "grains per species"),
    "geometry/statistics/volume_nm3": (("species",), "nm3", "grain volume per species"),
    "geometry/statistics/pvc": (("species",), "1", "pigment volume concentration per species"),
    "geometry/statistics/profile_z_nm": (("z_edge",), "nm", "z bin edges of the volume profile"),
    "geometry/statistics/profile_fraction": (("z",), "1", "grain volume fraction per z bin"),
    "geometry/statistics/rdf_r_nm": (("r",), "nm", "centre distance"),
    "geometry/statistics/rdf": (("r",), "1", "pair correlation of the centres g(r)"),
    "geometry/statistics/cluster_sizes": (("cluster",), "1", "cluster sizes, largest first"),
    "geometry/statistics@pvc_total": ((), "1", "total pigment volume concentration"),
    "geometry/statistics@min_gap_nm": ((), "nm", "smallest surface gap"),
    "geometry/statistics@worst_overlap_nm": ((), "nm", "worst overlap"),
    "geometry/statistics@mean_diameter_nm": ((), "nm", "mean grain diameter"),
    "geometry/statistics@protrusion_nm": ((), "nm", "surface protrusion"),
    "geometry/statistics@bottom_excess_nm": ((), "nm", "excess below the layer"),
    "geometry/statistics@rdf_slab_nm": ((), "nm", "slab thickness of the g(r) normalisation"),
    "geometry/statistics@contact_gap_nm": ((), "nm", "gap counted as contact"),
    "geometry/statistics@order_parameter": ((), "1", "orientational order parameter"),
    # realisations
    "realisations/seed": (("realisation",), None, "seed of the realisation"),
    "realisations/achieved_pvc": (("realisation",), "1", "achieved PVC of the realisation"),
    # one solve (group attributes and datasets)
    "solves/*@wavelength_nm": ((), "nm", "vacuum wavelength"),
    "solves/*@polar_deg": ((), "deg", "polar angle of incidence"),
    "solves/*@azimuth_deg": ((), "deg", "azimuth of incidence"),
    "solves/*@total_reflectance": ((), "1", "total reflectance"),
    "solves/*@total_transmittance": ((), "1", "total transmittance"),
    "solves/*@absorption": ((), "1", "absorption"),
    "solves/*@energy_balance": ((), "1", "R + T + A - 1"),
    "solves/*@r00": ((), "1", "specular reflection amplitude"),
    "solves/*@t00": ((), "1", "direct transmission amplitude"),
    "solves/*@method": ((), None, "solver method used"),
    "solves/*@side": ((), None, "face lit (below: layer flipped)"),
    "solves/*@realisation": ((), None, "realisation index"),
    "solves/*@iterations": ((), "1", "iterations"),
    "solves/*@operator_applications": ((), "1", "operator applications"),
    "solves/*@residual": ((), "1", "relative residual"),
    "solves/*@seconds": ((), "s", "solve time"),
    "solves/*@note": ((), None, "why this method"),
    "solves/*@equation": ((), None, "wave equation solved (helmholtz: scalar, maxwell: vector)"),
    "solves/*@polarisation": ((), None, "incident polarisation (unpolarised, s, p; none: scalar wave)"),
    "solves/*@random_phase_deg": ((), "deg", "relative phase of p to s of a random-phase natural-light solve (NaN: s and p solved apart, or scalar)"),
    "solves/*@total_reflectance_s": ((), "1", "total reflectance, s-polarised incidence"),
    "solves/*@total_reflectance_p": ((), "1", "total reflectance, p-polarised incidence"),
    "solves/*@total_transmittance_s": ((), "1", "total transmittance, s-polarised incidence"),
    "solves/*@total_transmittance_p": ((), "1", "total transmittance, p-polarised incidence"),
    "solves/*@absorption_s": ((), "1", "absorption, s-polarised incidence"),
    "solves/*@absorption_p": ((), "1", "absorption, p-polarised incidence"),
    "solves/*@energy_balance_s": ((), "1", "R + T + A - 1, s-polarised incidence"),
    "solves/*@energy_balance_p": ((), "1", "R + T + A - 1, p-polarised incidence"),
    "solves/*/orders_mn": (("order", "mn"), None, "diffraction order indices m, n"),
    "solves/*/orders_theta_deg": (("order",), "deg", "polar angle of the order"),
    "solves/*/orders_phi_deg": (("order",), "deg", "azimuth of the order"),
    "solves/*/orders_reflectance": (("order",), "1", "reflected efficiency of the order"),
    "solves/*/orders_transmittance": (("order",), "1", "transmitted efficiency of the order"),
    "solves/*/orders_reflectance_s": (("order",), "1", "reflected efficiency of the order, s-polarised incidence"),
    "solves/*/orders_reflectance_p": (("order",), "1", "reflected efficiency of the order, p-polarised incidence"),
    "solves/*/orders_transmittance_s": (("order",), "1", "transmitted efficiency of the order, s-polarised incidence"),
    "solves/*/orders_transmittance_p": (("order",), "1", "transmitted efficiency of the order, p-polarised incidence"),
    # appearance
    "appearance/wavelengths_nm": (("wavelength_nm",), "nm", "vacuum wavelength"),
    "appearance/above_deg": (("above_deg",), "deg", "polar angle of incidence from above"),
    "appearance/illumination_deg": (("illumination_deg",), "deg", "illumination polar angle"),
    "appearance/viewing_deg": (("viewing_deg",), "deg", "viewing polar angle"),
    "appearance/below_deg": (("below_deg",), "deg", "polar angle of incidence from below"),
    "appearance@azimuth_deg": ((), "deg", "azimuth of the plane of incidence"),
    "appearance@table_cell": ((), "1", "angular table node spacing in sin θ"),
    "appearance@realisations": ((), None, "realisations averaged"),
    "appearance@paper_albedo": ((), "1", "Lambertian paper albedo"),
    "appearance/reflectance": (("wavelength_nm", "above_deg"), "1", "total reflectance"),
    "appearance/transmittance": (("wavelength_nm", "above_deg"), "1", "total transmittance"),
    "appearance/absorption": (("wavelength_nm", "above_deg"), "1", "absorption"),
    "appearance/specular_coherent": (("wavelength_nm", "above_deg"), "1", "coherent specular reflectance |<r00>|²"),
    "appearance/specular_incoherent": (("wavelength_nm", "above_deg"), "1", "incoherent specular reflectance <|r00|²> - |<r00>|²"),
    "appearance/direct_coherent": (("wavelength_nm", "above_deg"), "1", "coherent direct transmittance |<t00>|²"),
    "appearance/direct_incoherent": (("wavelength_nm", "above_deg"), "1", "incoherent direct transmittance <|t00|²> - |<t00>|²"),
    "appearance/brdf_table": (("wavelength_nm", "illumination_deg", "sy", "sx"), "sr-1", "diffuse BRDF density per projected solid angle on the table nodes (f = density / coverage)"),
    "appearance/btdf_table": (("wavelength_nm", "illumination_deg", "sy", "sx"), "sr-1", "diffuse BTDF density per projected solid angle on the table nodes (f = density / coverage)"),
    "appearance/table_coverage": (("sy", "sx"), "1", "share of each table node's kernel above the horizon"),
    "appearance/brdf_diffuse": (("wavelength_nm", "illumination_deg", "viewing_deg"), "sr-1", "layer diffuse BRDF, plane of incidence, specular side"),
    "appearance/btdf_diffuse": (("wavelength_nm", "illumination_deg", "viewing_deg"), "sr-1", "layer diffuse BTDF, plane of incidence, forward side"),
    "appearance/r_dd_up": (("wavelength_nm",), "1", "layer albedo for diffuse light from below"),
    "appearance/t_d": (("wavelength_nm",), "1", "layer diffuse transmittance"),
    "appearance/brdf_total": (("wavelength_nm", "illumination_deg", "viewing_deg"), "sr-1", "diffuse BRDF of layer + paper, plane of incidence"),
    "appearance/natural": (("wavelength_nm", "viewing_deg"), "1", "radiance factor under a uniform white sky"),
    "appearance/tile_srgb8": (("viewing_deg", "tile_column", "rgb"), None, "tile colour, sRGB 8 bit"),
    "appearance/tile_lab": (("viewing_deg", "tile_column", "lab"), "1", "tile colour, CIELAB (D65 white)"),
    "appearance/natural_srgb8": (("viewing_deg", "rgb"), None, "colour under a white sky, sRGB 8 bit"),
    "appearance/natural_lab": (("viewing_deg", "lab"), "1", "colour under a white sky, CIELAB (D65 white)"),
    "appearance/tile_png": (("byte",), None, "the tile as PNG"),
    "picture_png": (("byte",), None, "the orders picture as PNG"),
    # summary.h5 of a study
    "study/name": (("variant",), None, "variant name"),
    "study/id": (("variant",), None, "variant id (first 8 hex digits of SHA-256 of the name)"),
    "study/seed": (("variant",), None, "variant seed"),
    "study/mean_reflectance": (("variant",), "1", "mean total reflectance over the solves from above"),
    "study/mean_transmittance": (("variant",), "1", "mean total transmittance over the solves from above"),
    "study/mean_absorption": (("variant",), "1", "mean absorption over the solves from above"),
    "study/natural_srgb8": (("variant", "rgb"), None, "colour under natural light at the first viewing angle, sRGB 8 bit"),
    "study/natural_lab": (("variant", "lab"), "1", "colour under natural light at the first viewing angle, CIELAB (D65)"),
    "study/has_colour": (("variant",), None, "1 when the result has /appearance"),
}

# Names of the table node coordinates (not stored: derived from table_cell).
DERIVED = {
    "sx": ("1", "s_x = sin θ cos φ of the table node"),
    "sy": ("1", "s_y = sin θ sin φ of the table node"),
    "theta_deg": ("deg", "polar angle of the table node (NaN beyond the horizon)"),
    "phi_deg": ("deg", "azimuth of the table node"),
    "tile_illumination_deg": ("deg", "illumination angle of the tile column (NaN: the sky strip)"),
}


def lookup(key: str) -> Tuple[Tuple[str, ...], Optional[str], str]:
    """Layout entry for a path (``solves/0003/...`` matches ``solves/*/...``)."""
    if key in LAYOUT:
        return LAYOUT[key]
    parts = key.split("/")
    if len(parts) >= 2 and parts[0] == "solves":
        generic = "/".join(["solves", "*"] + parts[2:])
        generic = generic.replace("*/@", "*@")
        if generic in LAYOUT:
            return LAYOUT[generic]
        if "@" in parts[1]:
            g = "solves/*@" + parts[1].split("@", 1)[1]
            if g in LAYOUT:
                return LAYOUT[g]
    if key.endswith("_se"):
        dims, units, name = lookup(key[:-3])
        return dims, units, "standard error of the " + name
    raise KeyError(key)


def units_of(key: str, stored: Optional[object] = None) -> Optional[str]:
    """Units of ``key``: the stored HDF5 ``units`` attribute when given,
    otherwise the table's."""
    if stored is not None:
        if isinstance(stored, bytes):
            return stored.decode("utf-8")
        return str(stored)
    try:
        return lookup(key)[1]
    except KeyError:
        return None


_PRETTY = {
    "deg": "°",
    "degree": "°",
    "degrees": "°",
    "sr-1": "sr⁻¹",
    "sr^-1": "sr⁻¹",
    "1/sr": "sr⁻¹",
    "sr**-1": "sr⁻¹",
    "nm3": "nm³",
    "nm^3": "nm³",
    "1": "",
    "": "",
}


def pretty_units(units: Optional[str]) -> str:
    """Units as an axis label shows them: ``deg`` → ``°``, ``sr-1`` → ``sr⁻¹``."""
    if units is None:
        return ""
    return _PRETTY.get(units.strip(), units.strip())


def axis_label(name: str, units: Optional[str]) -> str:
    """``"name (units)"``, or just the name for dimensionless quantities."""
    u = pretty_units(units)
    return f"{name} ({u})" if u else name
