//! The expansion of a checked [`Study`] into named, seeded, validated
//! variants for one profile (the order and the rules are in the
//! [module docs](super)): the product's combinations, less the excluded
//! ones, then the explicit variants; each scene built from the base and its
//! overrides and checked by [`config::parse_scene`]. An invalid scene is
//! reported with the override most likely behind it ([`blame`]).

use super::keypath::{apply_override, remove_path};
use super::{
    sanitise, variant_id, variant_seed, Expansion, Override, Study, Variant, VariantScene,
};
use crate::config::{self, paint::PaintScene, Scene};
use crate::study::StudyError;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// A variant before its scene is built: name, labels, and the overrides
/// (with where each comes from) on top of the base and the profile.
struct Pending {
    name: String,
    labels: Vec<(String, String)>,
    sets: Vec<(String, Override)>,
    /// Key paths removed after the sets, with where each comes from.
    removes: Vec<(String, String)>,
    /// Where the variant comes from, for errors.
    origin: String,
}

impl Study {
    /// Expand the sweep for a profile into validated variants. Every error
    /// (bad key in an axis, exclusion matching nothing, duplicate names,
    /// invalid scene) is reported here, before any work.
    pub fn expand(&self, profile: Option<&str>) -> Result<Expansion, StudyError> {
        self.expand_as::<Scene>(profile)
    }

    /// The same for a study whose base is an effect paint ([`Study::is_paint`]).
    pub fn expand_paint(&self, profile: Option<&str>) -> Result<Expansion<PaintScene>, StudyError> {
        self.expand_as::<PaintScene>(profile)
    }

    fn expand_as<S: VariantScene>(
        &self,
        profile: Option<&str>,
    ) -> Result<Expansion<S>, StudyError> {
        if self.is_paint() != S::PAINT {
            return Err(self.err(if self.is_paint() {
                "the base is an effect paint ([paint]): this command takes a study of \
                 wave-optics layers (plan, run, check and merge take both)"
                    .into()
            } else {
                "the base is a wave-optics layer, not an effect paint ([paint])".into()
            }));
        }
        let profile = self.resolve_profile(profile)?;
        let study_dir = self.study_dir(profile.as_deref());
        let variants_dir = study_dir.join("variants");
        let prof: &[Override] = profile
            .as_deref()
            .and_then(|p| self.profiles.get(p))
            .map_or(&[], Vec::as_slice);

        let choices = self.excluded(self.choices())?;
        let mut pending: Vec<Pending> = choices.iter().map(|c| self.combination(c)).collect();
        pending.extend((0..self.explicit.len()).map(|i| self.explicit_variant(i)));
        if pending.is_empty() {
            return Err(
                self.err("the study has no variants: add [[axis]] or [[variant]] tables".into())
            );
        }
        let mut seen: HashMap<String, usize> = HashMap::new();
        for (i, p) in pending.iter().enumerate() {
            if let Some(j) = seen.insert(p.name.clone(), i) {
                return Err(self.err(format!(
                    "two variants are named `{}`: ({}) and ({}); names must be unique — \
                     make the labels distinct (after sanitising to A-Z a-z 0-9 _ . -)",
                    p.name, pending[j].origin, p.origin
                )));
            }
        }

        let mut variants = Vec::with_capacity(pending.len());
        for (index, p) in pending.into_iter().enumerate() {
            variants.push(self.variant(index, p, prof, profile.as_deref(), &variants_dir)?);
        }
        Ok(Expansion {
            profile,
            study_dir,
            variants,
            selection: vec![],
        })
    }

    /// The combinations of the product: for each, the value index per axis
    /// (`None` = no label), the last group varying fastest.
    fn choices(&self) -> Vec<Vec<Option<usize>>> {
        let mut choices: Vec<Vec<Option<usize>>> = vec![];
        if !self.axes.is_empty() {
            let mut counter = vec![0usize; self.groups.len()];
            let n_total = self.product_size();
            for _ in 0..n_total {
                let mut c = vec![None; self.axes.len()];
                for (g, members) in self.groups.iter().enumerate() {
                    for &a in members {
                        c[a] = Some(counter[g]);
                    }
                }
                choices.push(c);
                for g in (0..self.groups.len()).rev() {
                    counter[g] += 1;
                    if counter[g] < self.axes[self.groups[g][0]].values.len() {
                        break;
                    }
                    counter[g] = 0;
                }
            }
        }
        choices
    }

    /// `choices` less the excluded ones; an exclusion that drops nothing is
    /// an error.
    fn excluded(
        &self,
        mut choices: Vec<Vec<Option<usize>>>,
    ) -> Result<Vec<Vec<Option<usize>>>, StudyError> {
        let label_of = |c: &[Option<usize>], a: usize| c[a].map(|j| &self.axes[a].values[j].label);
        let mut hits = vec![0usize; self.excludes.len()];
        choices.retain(|c| {
            let mut keep = true;
            for (k, ex) in self.excludes.iter().enumerate() {
                let m = ex.iter().all(|(a, l)| {
                    let i = self.axes.iter().position(|x| &x.name == a);
                    i.and_then(|i| label_of(c, i)) == Some(l)
                });
                if m {
                    hits[k] += 1;
                    keep = false;
                }
            }
            keep
        });
        for (k, h) in hits.iter().enumerate() {
            if *h == 0 {
                let desc: Vec<String> = self.excludes[k]
                    .iter()
                    .map(|(a, l)| format!("{a} = \"{l}\""))
                    .collect();
                return Err(self.err(format!(
                    "[[exclude]] {} ({}) matches no combination of the axes; remove it or fix it \
                     (zipped axes only combine label by label)",
                    k + 1,
                    desc.join(", ")
                )));
            }
        }
        Ok(choices)
    }

    /// The variant of one combination: named by its labels.
    fn combination(&self, c: &[Option<usize>]) -> Pending {
        let mut labels = vec![];
        let mut sets = vec![];
        let mut removes = vec![];
        for (a, axis) in self.axes.iter().enumerate() {
            if let Some(j) = c[a] {
                let v = &axis.values[j];
                labels.push((axis.name.clone(), v.label.clone()));
                let src = format!("axis `{}` value `{}`", axis.name, v.label);
                sets.extend(v.set.iter().map(|o| (src.clone(), o.clone())));
                removes.extend(v.remove.iter().map(|k| (src.clone(), k.clone())));
            }
        }
        let name = labels
            .iter()
            .map(|(_, l)| sanitise(l))
            .collect::<Vec<_>>()
            .join("_");
        let origin = labels
            .iter()
            .map(|(a, l)| format!("{a} = {l}"))
            .collect::<Vec<_>>()
            .join(", ");
        Pending {
            name,
            labels,
            sets,
            removes,
            origin,
        }
    }

    /// Explicit variant `i`: its axis values' overrides, then its `set`.
    fn explicit_variant(&self, i: usize) -> Pending {
        let ev = &self.explicit[i];
        let mut labels = vec![];
        let mut sets = vec![];
        let mut removes = vec![];
        for axis in &self.axes {
            if let Some(l) = ev.labels.get(&axis.name) {
                if let Some(v) = axis.values.iter().find(|v| &v.label == l) {
                    labels.push((axis.name.clone(), l.clone()));
                    let src = format!("axis `{}` value `{l}`", axis.name);
                    sets.extend(v.set.iter().map(|o| (src.clone(), o.clone())));
                    removes.extend(v.remove.iter().map(|k| (src.clone(), k.clone())));
                }
            }
        }
        for o in &ev.set {
            sets.push((format!("[[variant]] `{}`", ev.name), o.clone()));
        }
        Pending {
            name: ev.name.clone(),
            labels,
            sets,
            removes,
            origin: format!("[[variant]] {}", i + 1),
        }
    }

    /// Build and check the scene of variant number `index`.
    fn variant<S: VariantScene>(
        &self,
        index: usize,
        p: Pending,
        prof: &[Override],
        profile: Option<&str>,
        variants_dir: &Path,
    ) -> Result<Variant<S>, StudyError> {
        let mut table = self.base.clone();
        for o in prof {
            apply_override(&mut table, o).map_err(|m| {
                self.err(format!(
                    "[profiles.{}]: key path `{}`: {m}",
                    profile.unwrap_or(""),
                    o.key
                ))
            })?;
        }
        for (src, o) in &p.sets {
            apply_override(&mut table, o).map_err(|m| {
                self.err(format!(
                    "{src}: key path `{}`: {m} (variant `{}`)",
                    o.key, p.name
                ))
            })?;
        }
        for (src, k) in &p.removes {
            remove_path(&mut table, k).map_err(|m| {
                self.err(format!("{src}: remove `{k}`: {m} (variant `{}`)", p.name))
            })?;
        }
        let seed = variant_seed(self.seed, &p.name);
        if S::SEEDED {
            table.insert("seed".into(), Value::Integer(seed as i64));
        }
        let mut out = Table::new();
        out.insert(
            "dir".into(),
            Value::String(variants_dir.to_string_lossy().into_owned()),
        );
        out.insert("name".into(), Value::String(p.name.clone()));
        table.insert("output".into(), Value::Table(out));
        let text = toml::to_string(&table)
            .map_err(|e| self.err(format!("variant `{}`: cannot write its scene: {e}", p.name)))?;
        let scene_path = PathBuf::from(format!("{}#{}", self.base_path.display(), p.name));
        let scene = S::parse(&scene_path, &text).map_err(|e| {
            let blame = blame(&e, prof, &p.sets, profile);
            self.err(format!(
                "variant `{}` ({}) is not a valid scene: {e}{blame}",
                p.name, p.origin
            ))
        })?;
        if let Some(problem) = scene.study_problem() {
            return Err(self.err(format!("variant `{}` ({}): {problem}", p.name, p.origin)));
        }
        Ok(Variant {
            index,
            id: variant_id(&p.name),
            name: p.name,
            labels: p.labels,
            seed,
            text,
            scene,
        })
    }
}

/// Which override is likely behind a scene error: the one whose key path
/// contains the offending key or the unknown field.
fn blame(
    e: &config::ConfigError,
    prof: &[Override],
    sets: &[(String, Override)],
    profile: Option<&str>,
) -> String {
    let needle: Option<String> = match e {
        config::ConfigError::Invalid { key, .. } => Some(
            key.split(['.', '['])
                .next_back()
                .unwrap_or("")
                .trim_end_matches(']')
                .to_string(),
        ),
        config::ConfigError::Parse { message, .. } => message
            .split("unknown field `")
            .nth(1)
            .and_then(|s| s.split('`').next())
            .map(str::to_string)
            .or_else(|| {
                message
                    .split("unknown variant `")
                    .nth(1)
                    .and_then(|s| s.split('`').next())
                    .map(str::to_string)
            }),
        _ => None,
    };
    let Some(n) = needle.filter(|n| !n.is_empty()) else {
        return String::new();
    };
    let hit = |o: &Override| {
        o.key.split('.').any(|s| s == n) || o.value.to_string().contains(&format!("\"{n}\""))
    };
    if let Some((src, o)) = sets.iter().rev().find(|(_, o)| hit(o)) {
        return format!(" — set by {src} (key path `{}`)", o.key);
    }
    if let Some(o) = prof.iter().find(|o| hit(o)) {
        return format!(
            " — set by [profiles.{}] (key path `{}`)",
            profile.unwrap_or(""),
            o.key
        );
    }
    String::new()
}
