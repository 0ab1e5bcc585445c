//! The fragments of a stack's layers as one fragment: each layer's grains
//! moved down by the thickness of the layers above it (`z` grows downwards
//! from the top surface at `z = 0`), their species numbered after the
//! layers above.

use super::{Geometry, GeometryStats, Particle, Sphere};

/// One layer's fragment and how many species its scene has (a species
/// without grains still takes its number).
pub struct StackPart<'a> {
    pub geometry: &'a Geometry,
    pub species: usize,
}

/// A fragment without grains (a layer of dissolved pigments): its size and
/// its species' fractions, none placed as grains.
pub fn without_grains(size_nm: [f64; 3], fractions: Vec<f64>) -> Geometry {
    Geometry {
        size_nm,
        particles: Vec::new(),
        stats: GeometryStats {
            count: vec![0; fractions.len()],
            target_fraction: fractions.clone(),
            achieved_fraction: fractions,
            min_gap_nm: f64::INFINITY,
            attempts: 0,
            worst_overlap_nm: 0.0,
            order_parameter: None,
            relax_steps: 0,
        },
    }
}

/// The layers' fragments, top first, as one fragment of their summed
/// thickness (lateral size: the top layer's; a coherent stack has one).
/// Fractions are of the whole: each layer's scaled by its share of the
/// thickness.
pub fn stacked(parts: &[StackPart<'_>]) -> Geometry {
    let total: f64 = parts.iter().map(|p| p.geometry.size_nm[2]).sum();
    let mut particles = Vec::new();
    let mut stats = GeometryStats {
        count: Vec::new(),
        target_fraction: Vec::new(),
        achieved_fraction: Vec::new(),
        min_gap_nm: f64::INFINITY,
        attempts: 0,
        worst_overlap_nm: 0.0,
        order_parameter: None,
        relax_steps: 0,
    };
    let (mut dz, mut first_species) = (0.0, 0);
    let mut order = (0.0, 0usize); // Σ S × particles with an axis, and their count
    for p in parts {
        let g = p.geometry;
        for q in &g.particles {
            particles.push(Particle {
                species: first_species + q.species,
                spheres: q
                    .spheres
                    .iter()
                    .map(|s| Sphere {
                        center: [s.center[0], s.center[1], s.center[2] + dz],
                        radius: s.radius,
                    })
                    .collect(),
            });
        }
        let share = if total > 0.0 {
            g.size_nm[2] / total
        } else {
            0.0
        };
        let st = &g.stats;
        let pad = |v: &[f64], scale: f64| -> Vec<f64> {
            (0..p.species)
                .map(|s| v.get(s).copied().unwrap_or(0.0) * scale)
                .collect()
        };
        stats
            .count
            .extend((0..p.species).map(|s| st.count.get(s).copied().unwrap_or(0)));
        stats
            .target_fraction
            .extend(pad(&st.target_fraction, share));
        stats
            .achieved_fraction
            .extend(pad(&st.achieved_fraction, share));
        stats.min_gap_nm = stats.min_gap_nm.min(st.min_gap_nm);
        stats.attempts += st.attempts;
        stats.worst_overlap_nm = stats.worst_overlap_nm.max(st.worst_overlap_nm);
        stats.relax_steps += st.relax_steps;
        if let Some(s) = st.order_parameter {
            let n = g.particles.iter().filter(|q| q.spheres.len() > 1).count();
            order.0 += s * n as f64;
            order.1 += n;
        }
        dz += g.size_nm[2];
        first_species += p.species;
    }
    if order.1 > 0 {
        stats.order_parameter = Some(order.0 / order.1 as f64);
    }
    let size_nm = parts.first().map_or([0.0, 0.0, total], |p| {
        [p.geometry.size_nm[0], p.geometry.size_nm[1], total]
    });
    Geometry {
        size_nm,
        particles,
        stats,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(species: usize, z: f64, h: f64, fraction: f64) -> Geometry {
        Geometry {
            size_nm: [100.0, 100.0, h],
            particles: vec![Particle {
                species,
                spheres: vec![Sphere {
                    center: [10.0, 20.0, z],
                    radius: 5.0,
                }],
            }],
            stats: GeometryStats {
                count: vec![1],
                target_fraction: vec![fraction],
                achieved_fraction: vec![fraction],
                min_gap_nm: 3.0,
                attempts: 4,
                worst_overlap_nm: 0.0,
                order_parameter: None,
                relax_steps: 0,
            },
        }
    }

    #[test]
    fn lower_layers_move_down_and_renumber_their_species() {
        let (a, b) = (one(0, 30.0, 100.0, 0.2), one(0, 50.0, 300.0, 0.4));
        let g = stacked(&[
            StackPart {
                geometry: &a,
                species: 1,
            },
            StackPart {
                geometry: &b,
                species: 1,
            },
        ]);
        assert_eq!(g.size_nm, [100.0, 100.0, 400.0]);
        assert_eq!(g.particles[0].spheres[0].center, [10.0, 20.0, 30.0]);
        assert_eq!(g.particles[1].spheres[0].center, [10.0, 20.0, 150.0]);
        assert_eq!(g.particles[1].species, 1);
        assert_eq!(g.stats.count, vec![1, 1]);
        // Fractions of the whole: 0.2 of a quarter, 0.4 of three quarters.
        assert!((g.stats.target_fraction[0] - 0.05).abs() < 1e-15);
        assert!((g.stats.achieved_fraction[1] - 0.3).abs() < 1e-15);
        assert_eq!(g.stats.attempts, 8);
    }
}
