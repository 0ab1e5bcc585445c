//! `/geometry`: the particle set and, with grains, its statistics, every
//! dataset with its units, meaning and axes.

use ndarray::Array2;

use super::attrs::{vlu, write_scalar_attr};
use super::described::{about, dim, Scales};
use crate::geometry::Statistics;

/// Statistics of the generated fragment. Sphere arrays (`centers_nm`,
/// `radii_nm`, `particle_of_sphere`) share one length, species arrays
/// (`species_names` and the three fractions) another.
#[derive(Debug, Clone, Copy)]
pub struct GeometrySummary<'a> {
    pub species_names: &'a [String],
    pub centers_nm: &'a [[f64; 3]],
    pub radii_nm: &'a [f64],
    pub particle_of_sphere: &'a [u32],
    pub species_of_particle: &'a [u32],
    pub target_fraction: &'a [f64],
    pub achieved_fraction: &'a [f64],
    pub raster_fraction: &'a [f64],
    /// Smallest surface gap between grains (None: no grains).
    pub min_gap_nm: Option<f64>,
    /// Full statistics of the fragment (None: no grains).
    pub statistics: Option<&'a Statistics>,
}

/// Write `/geometry` (with `/geometry/statistics` when there are grains).
pub(super) fn write_geometry(
    s: &mut Scales,
    file: &hdf5::File,
    g: &GeometrySummary,
) -> hdf5::Result<()> {
    let geo = file.create_group("geometry")?;
    let names = g
        .species_names
        .iter()
        .map(|s| vlu(s))
        .collect::<hdf5::Result<Vec<_>>>()?;
    let description = "pigment species names (labels, no units); species";
    s.coordinate(
        &geo,
        "species_names",
        &names,
        about("", description, &[dim::SPECIES]),
    )?;
    let centers = Array2::from_shape_fn((g.centers_nm.len(), 3), |(i, j)| g.centers_nm[i][j]);
    let description = "sphere centres x, y, z; sphere × xyz";
    s.write(
        &geo,
        "centers_nm",
        &centers,
        about("nm", description, &[dim::SPHERE, dim::XYZ]),
    )?;
    let sphere = &[dim::SPHERE][..];
    s.write(
        &geo,
        "radii_nm",
        g.radii_nm,
        about("nm", "sphere radii; sphere", sphere),
    )?;
    let description = "index of the particle (grain) each sphere belongs to; sphere";
    s.write(
        &geo,
        "particle_of_sphere",
        g.particle_of_sphere,
        about("1", description, sphere),
    )?;
    let description = "index into species_names of each particle; particle";
    let particle = &[dim::PARTICLE][..];
    s.write(
        &geo,
        "species_of_particle",
        g.species_of_particle,
        about("1", description, particle),
    )?;
    for (name, v, what) in [
        ("target_fraction", g.target_fraction, "target"),
        (
            "achieved_fraction",
            g.achieved_fraction,
            "achieved (packed spheres)",
        ),
        (
            "raster_fraction",
            g.raster_fraction,
            "rasterised (on the grid)",
        ),
    ] {
        let description = format!("{what} volume fraction of each species in the layer; species");
        s.write(&geo, name, v, about("1", &description, &[dim::SPECIES]))?;
    }
    if let Some(gap) = g.min_gap_nm {
        write_scalar_attr(&geo, "min_gap_nm", gap)?;
    }
    if let Some(st) = g.statistics {
        write_statistics(s, &geo.create_group("statistics")?, st)?;
    }
    Ok(())
}

fn write_statistics(s: &mut Scales, g: &hdf5::Group, st: &Statistics) -> hdf5::Result<()> {
    for (name, v) in [
        ("pvc_total", st.pvc_total),
        ("min_gap_nm", st.min_gap_nm),
        ("worst_overlap_nm", st.worst_overlap_nm),
        ("mean_diameter_nm", st.mean_diameter_nm),
        ("protrusion_nm", st.protrusion_nm),
        ("bottom_excess_nm", st.bottom_excess_nm),
        ("rdf_slab_nm", st.rdf_slab_nm),
        ("contact_gap_nm", st.contact_gap_nm),
    ] {
        write_scalar_attr(g, name, v)?;
    }
    if let Some(order) = st.order_parameter {
        write_scalar_attr(g, "order_parameter", order)?;
    }
    let count: Vec<u64> = st.count.iter().map(|&c| c as u64).collect();
    let clusters: Vec<u64> = st.cluster_sizes.iter().map(|&c| c as u64).collect();
    let species = &[dim::SPECIES][..];
    s.write(
        g,
        "count",
        &count[..],
        about("1", "grains per species; species", species),
    )?;
    let description = "sizes of the clusters of touching grains, largest first; cluster";
    s.write(
        g,
        "cluster_sizes",
        &clusters[..],
        about("1", description, &[dim::CLUSTER]),
    )?;
    let description = "grain volume per species; species";
    s.write(
        g,
        "volume_nm3",
        &st.volume_nm3[..],
        about("nm3", description, species),
    )?;
    let description = "pigment volume concentration per species; species";
    s.write(g, "pvc", &st.pvc[..], about("1", description, species))?;
    let description =
        "edges of the z bins of the volume profile (z = 0 at the layer's bottom); z edge";
    s.write(
        g,
        "profile_z_nm",
        &st.profile_z_nm[..],
        about("nm", description, &[dim::Z_EDGE]),
    )?;
    let description = "grain volume fraction per z bin; z";
    s.write(
        g,
        "profile_fraction",
        &st.profile_fraction[..],
        about("1", description, &[dim::Z]),
    )?;
    let description = "centre distances of the pair correlation; r";
    s.coordinate(
        g,
        "rdf_r_nm",
        &st.rdf_r_nm[..],
        about("nm", description, &[dim::R]),
    )?;
    let description = "pair correlation g(r) of the grain centres; r";
    s.write(g, "rdf", &st.rdf[..], about("1", description, &[dim::R]))?;
    Ok(())
}
