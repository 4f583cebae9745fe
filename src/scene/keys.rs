//! The documentation of every scene key: one table ([`KEYS`]), one row per key, giving
//! its meaning, unit, allowed range and default. `langevin-fem scene show` prints the
//! rows of the keys a scene uses ([`scene_keys`], [`document`]) after the scene as it will
//! run ([`effective_toml`]).
//!
//! Keys are written as patterns of their dotted path: `[]` for any element of an array of
//! tables and `<budget>` for any of `quick`, `standard`, `full`, e.g.
//! `runs[].<budget>.duration_tau1`. Arrays of values (`checks`, `two_time`) are one key.
//!
//! **Units.** Times are in units of the slowest relaxation time of the hinged filament,
//! τ₁ = ξL⁴/(π⁴EI), wherever the key ends in `_tau1`; strains in units of the Euler strain
//! ε_c0 = π²EI/(EA·L²); forces in units of the Euler load F_c0 = π²EI/L². The physical
//! parameters of `[filament]` are in the scene's own consistent units (any unit system:
//! e.g. µm, pN·µm² and pN·µm, or all 1).
//!
//! Tests hold the table to the scenes and to the validator: every key of every built-in
//! scene has a row, every row is a key the scene types accept, and every value just
//! outside a row's [`Bounds`] is refused by [`Scene::validate`] (naming the key) while the
//! bounds themselves, where closed, are not refused for this key.

use super::spec::Scene;
use crate::error::Result;
use toml::Value;

/// A fixed interval of a numeric key (of every element, for a list of numbers), as the
/// validator enforces it; keys whose range depends on other keys have none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Lower end.
    pub lo: f64,
    /// Whether `lo` itself is excluded.
    pub lo_open: bool,
    /// Upper end.
    pub hi: f64,
    /// Whether `hi` itself is excluded.
    pub hi_open: bool,
    /// Whether the key is a whole number.
    pub integer: bool,
}

/// `[lo, hi]` for a number.
const fn closed(lo: f64, hi: f64) -> Option<Bounds> {
    Some(Bounds {
        lo,
        lo_open: false,
        hi,
        hi_open: false,
        integer: false,
    })
}

/// `(lo, hi]` for a number.
const fn open_closed(lo: f64, hi: f64) -> Option<Bounds> {
    Some(Bounds {
        lo,
        lo_open: true,
        hi,
        hi_open: false,
        integer: false,
    })
}

/// `(lo, hi)` for a number.
const fn open(lo: f64, hi: f64) -> Option<Bounds> {
    Some(Bounds {
        lo,
        lo_open: true,
        hi,
        hi_open: true,
        integer: false,
    })
}

/// `[lo, hi]` for a whole number.
const fn count(lo: f64, hi: f64) -> Option<Bounds> {
    Some(Bounds {
        lo,
        lo_open: false,
        hi,
        hi_open: false,
        integer: true,
    })
}

/// The documentation of one scene key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyDoc {
    /// The key's path pattern, e.g. `runs[].<budget>.duration_tau1`.
    pub key: &'static str,
    /// What it means.
    pub meaning: &'static str,
    /// Its unit (`-` for a name, a count or a choice).
    pub unit: &'static str,
    /// The values the validator accepts.
    pub range: &'static str,
    /// The value when the key is left out, or `required`.
    pub default: &'static str,
    /// The fixed interval of [`Self::range`], if it is one (checked against the
    /// validator by a test).
    pub bounds: Option<Bounds>,
}

/// A row of [`KEYS`].
const fn key(
    key: &'static str,
    unit: &'static str,
    range: &'static str,
    default: &'static str,
    bounds: Option<Bounds>,
    meaning: &'static str,
) -> KeyDoc {
    KeyDoc {
        key,
        meaning,
        unit,
        range,
        default,
        bounds,
    }
}

/// The range of the physical parameters of `[filament]`.
const PHYSICAL: &str = "in [1e-30, 1e30]";
/// Unit of a physical parameter of `[filament]`.
const SCENE_UNITS: &str = "scene units";

/// Every key of a scene file, in the order of a scene file.
pub const KEYS: &[KeyDoc] = &[
    key(
        "description",
        "-",
        "a string",
        "required",
        None,
        "One-line description of the scene, shown in the reports and by `list`.",
    ),
    key(
        "seed",
        "-",
        "a whole number in [0, 9223372036854775807] (a TOML integer; `--seed` takes any u64)",
        "required",
        None,
        "Master seed: every trajectory's random stream derives from it, the run name and the trajectory index. `--seed N` replaces it.",
    ),
    key(
        "dims",
        "-",
        "2 or 3",
        "required",
        None,
        "Transverse directions: 2 (deflection w only) or 3 (w and v).",
    ),
    key(
        "model",
        "-",
        "\"fem\", \"spectral\" or \"compression\"",
        "required",
        None,
        "What is simulated: the linear filament of eq. (2) with Hermite-cubic finite elements (fem), the exact modal simulator of eq. (2) (spectral), or the finite-deflection (von Karman) filament under imposed end-shortening, the paper's Fig. 2 (compression).",
    ),
    key(
        "checks",
        "-",
        "a non-empty list of: profile, mode-variance, mode-distribution, decay-rate, spectrum, two-time (fem, spectral); force-strain, force-distribution, dt-halving (compression)",
        "required",
        None,
        "The statistical checks of every run that does not list its own.",
    ),
    // [filament]: physical parameters (one row per key; keys added here are documented
    // by adding a row).
    key(
        "filament.length",
        SCENE_UNITS,
        PHYSICAL,
        "1",
        closed(1e-30, 1e30),
        "Filament length L (a length).",
    ),
    key(
        "filament.bending_rigidity",
        SCENE_UNITS,
        PHYSICAL,
        "1",
        closed(1e-30, 1e30),
        "Bending rigidity EI (energy x length). With ξ and L it sets τ₁ = ξL⁴/(π⁴EI); EI/(kT·L) is the persistence length over the length.",
    ),
    key(
        "filament.stretch_rigidity",
        SCENE_UNITS,
        PHYSICAL,
        "1e6",
        closed(1e-30, 1e30),
        "Stretching rigidity EA (a force); used by the compression model only (EA·L/kT = 1e6 in the paper's Fig. 2).",
    ),
    key(
        "filament.drag",
        SCENE_UNITS,
        PHYSICAL,
        "1",
        closed(1e-30, 1e30),
        "Transverse drag coefficient per unit length ξ (force x time / length²).",
    ),
    key(
        "filament.kt",
        SCENE_UNITS,
        PHYSICAL,
        "1",
        closed(1e-30, 1e30),
        "Thermal energy k_B T (an energy).",
    ),
    key(
        "filament.contour_length_um",
        "µm",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Contour length L of a filament given in physical units (instead of `length`; then every physical key is physical). Converted to µm, s, pN.",
    ),
    key(
        "filament.persistence_length_um",
        "µm",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Persistence length ℓp; EI = ℓp·k_B·T (or give `bending_rigidity_pn_um2`, not both).",
    ),
    key(
        "filament.bending_rigidity_pn_um2",
        "pN·µm²",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Bending rigidity EI (or give `persistence_length_um`, not both).",
    ),
    key(
        "filament.stretch_rigidity_pn",
        "pN",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Stretching rigidity EA (optional; default EA·L/kT = 1e6).",
    ),
    key(
        "filament.viscosity_pa_s",
        "Pa·s",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Solvent viscosity η; with `diameter_nm` the drag per length is the slender-body ξ⊥ = 4πη/(ln(L/d) + 1/2) (or give `drag_pn_s_per_um2`).",
    ),
    key(
        "filament.diameter_nm",
        "nm",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Filament diameter d, for the slender-body drag (only with `viscosity_pa_s`; L/d >= 10).",
    ),
    key(
        "filament.drag_pn_s_per_um2",
        "pN·s/µm²",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Transverse drag per length ξ (instead of `viscosity_pa_s` and `diameter_nm`).",
    ),
    key(
        "filament.temperature_k",
        "K",
        "positive; the converted parameters must lie in [1e-30, 1e30]",
        "-",
        None,
        "Temperature T; kT = k_B·T (4.142 pN·nm at 300 K).",
    ),
    key(
        "mesh.elements",
        "-",
        "a whole number in [1, 1000]",
        "required",
        count(1.0, 1000.0),
        "Hermite-cubic elements (fem, compression), or modes (spectral).",
    ),
    key(
        "mesh.grading",
        "-",
        "in [0.01, 100]; 1 for model = \"compression\"",
        "1",
        closed(0.01, 100.0),
        "Ratio of the last to the first element length (geometric grading); 1 is a uniform mesh.",
    ),
    key(
        "sampling.burn_in_tau1",
        "τ₁",
        "in [0, 1e4], >= the largest η of sampling.two_time",
        "required in [sampling]",
        closed(0.0, 1e4),
        "Linear scenes: simulated time from rest (w = 0) before sampling starts.",
    ),
    key(
        "sampling.modes",
        "-",
        "a whole number in [1, min(50, 2 x mesh.elements)] (fem) or [1, min(50, mesh.elements)] (spectral)",
        "required in [sampling]",
        None,
        "Linear scenes: the number of lowest modes whose variance, distribution, decay rate and spectrum are checked.",
    ),
    key(
        "sampling.profile_points",
        "x/L",
        "at most 100 positions, each in (0, 1); non-empty when the checks have profile",
        "[]",
        open(0.0, 1.0),
        "Linear scenes: positions where the equilibrium profile ⟨w²(x)⟩ is checked.",
    ),
    key(
        "sampling.two_time",
        "[x/L, y/L, t/τ₁, η/τ₁]",
        "at most 100 points; x/L and y/L in (0, 1), 0 < t <= η <= sampling.burn_in_tau1; non-empty when the checks have two-time",
        "[]",
        None,
        "Linear scenes: points (x, y, t, η) of the two-time correlation ⟨w(x,t) w(y,η)⟩ from w(x, 0) = 0, eq. (4).",
    ),
    key(
        "compression.strain_ratios",
        "ε/ε_c0",
        "1 to 100 strains, each in [-1000, 1000]",
        "required",
        closed(-1000.0, 1000.0),
        "Compression scenes: imposed end-shortening strains ε = Δ/L in units of the Euler strain ε_c0 = π²EI/(EA·L²) (negative: tension).",
    ),
    key(
        "compression.distribution_strain_ratios",
        "ε/ε_c0",
        "values of compression.strain_ratios",
        "[]",
        None,
        "Compression scenes: strains where the distribution of F is tested against the exact equilibrium law.",
    ),
    key(
        "compression.burn_in_tau1",
        "τ₁",
        "in [0, 1e4]",
        "required",
        closed(0.0, 1e4),
        "Compression scenes: simulated time from rest at each strain before sampling.",
    ),
    key(
        "compression.sample_every_tau1",
        "τ₁",
        "in (0, 100]",
        "required",
        open_closed(0.0, 100.0),
        "Compression scenes: time between samples of the force F.",
    ),
    key(
        "compression.halving",
        "-",
        "two different run names of this scene; required when checks has dt-halving",
        "none",
        None,
        "Compression scenes: the runs [at Δt, at Δt/2] compared by the dt-halving check.",
    ),
    key(
        "runs[].name",
        "-",
        "non-empty [A-Za-z0-9_-], at most 64 characters, unique within the scene",
        "required",
        None,
        "The run's name (part of its output file names).",
    ),
    key(
        "runs[].integrator",
        "-",
        "euler-maruyama, backward-euler, crank-nicolson or exact-modal (fem, spectral); euler-maruyama, backward-euler, crank-nicolson or metropolis-crank-nicolson (compression)",
        "crank-nicolson",
        None,
        "Time integrator (the spectral model is exact and ignores it).",
    ),
    key(
        "runs[].noise",
        "-",
        "consistent or element-uniform (consistent for metropolis-crank-nicolson)",
        "consistent",
        None,
        "Noise model: consistent (nodal forces of covariance exactly 2kT·C/Δt) or element-uniform (the paper's uniform load per element, eq. 5).",
    ),
    key(
        "runs[].dt_tau1",
        "τ₁",
        "in (0, 100] (fem, spectral) or (0, compression.sample_every_tau1] (compression), at most 1e10 steps per trajectory, below the stability limit of an explicit integrator",
        "required",
        None,
        "Time step.",
    ),
    key(
        "runs[].checks",
        "-",
        "a non-empty list of the model's checks (dt-halving only in the scene's checks)",
        "the scene's checks",
        None,
        "The checks of this run, instead of the scene's.",
    ),
    key(
        "runs[].<budget>.trajectories",
        "-",
        "a whole number in [2, 100000] (per strain for compression)",
        "required",
        count(2.0, 100_000.0),
        "Independent trajectories, each started from rest, at this budget (quick, standard or full; `--budget` picks one).",
    ),
    key(
        "runs[].<budget>.duration_tau1",
        "τ₁",
        "fem, spectral: in [16, 1e6] and >= 256 x dt_tau1; compression: in [16 x compression.sample_every_tau1, 1e6]",
        "required unless target_std_error is given",
        None,
        "Sampled duration of each trajectory after the burn-in.",
    ),
    key(
        "runs[].<budget>.two_time_trajectories",
        "-",
        "a whole number in [0, 100000] (fem, spectral); 0 for compression",
        "0",
        count(0.0, 100_000.0),
        "Extra short trajectories (from rest to the largest η) for the two-time check only.",
    ),
    key(
        "runs[].<budget>.target_std_error",
        "F_c0",
        "in (0, 1] (compression only; with pilot_tau1 and max_duration_tau1, instead of duration_tau1)",
        "none",
        open_closed(0.0, 1.0),
        "Budget by target precision: the aimed standard error of ⟨F⟩ at every strain, in units of the Euler load F_c0 = π²EI/L².",
    ),
    key(
        "runs[].<budget>.pilot_tau1",
        "τ₁",
        "as duration_tau1, and <= max_duration_tau1",
        "required with target_std_error",
        None,
        "Budget by target precision: sampled duration of each pilot trajectory (the pilot predicts the duration that reaches the target).",
    ),
    key(
        "runs[].<budget>.max_duration_tau1",
        "τ₁",
        "as duration_tau1",
        "required with target_std_error",
        None,
        "Budget by target precision: the longest sampled duration of a main-stage trajectory.",
    ),
    key(
        "runs[].<budget>.max_dt_tau1",
        "τ₁",
        "in [dt_tau1, 100]; metropolis-crank-nicolson only, with min_acceptance",
        "none (no step search)",
        None,
        "Step search: the largest step tried (dt_tau1 x 2^k up to this).",
    ),
    key(
        "runs[].<budget>.min_acceptance",
        "-",
        "in (0, 1), with max_dt_tau1",
        "none",
        open(0.0, 1.0),
        "Step search: the acceptance rate a step must reach to be used.",
    ),
];

/// Whether the concrete key `path` (e.g. `runs[].quick.dt_tau1`) matches `pattern`:
/// segment by segment, `<budget>` matching `quick`, `standard` or `full`.
pub fn matches(pattern: &str, path: &str) -> bool {
    let (p, k): (Vec<&str>, Vec<&str>) = (pattern.split('.').collect(), path.split('.').collect());
    p.len() == k.len()
        && p.iter().zip(&k).all(|(p, k)| {
            p == k || (*p == "<budget>" && matches!(*k, "quick" | "standard" | "full"))
        })
}

/// The row documenting the concrete key `path`, if any.
pub fn doc(path: &str) -> Option<&'static KeyDoc> {
    KEYS.iter().find(|d| matches(d.key, path))
}

/// The keys of a scene's TOML value, in order and without repeats: every value that is
/// not a table, with `[]` for an element of an array of tables (`runs[].name`).
pub fn key_paths(value: &Value) -> Vec<String> {
    fn walk(v: &Value, prefix: &str, out: &mut Vec<String>) {
        let Value::Table(t) = v else { return };
        for (k, v) in t {
            let path = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            match v {
                Value::Table(_) => walk(v, &path, out),
                Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_table) => {
                    for e in a {
                        walk(e, &format!("{path}[]"), out);
                    }
                }
                _ => {
                    if !out.contains(&path) {
                        out.push(path);
                    }
                }
            }
        }
    }
    let mut out = Vec::new();
    walk(value, "", &mut out);
    out
}

/// The scene as it will run, as TOML text: every key with its value, defaults filled
/// in, in the order of the scene types.
///
/// # Errors
/// [`crate::Error::Numerical`] if the scene cannot be written as TOML (not for a valid
/// scene).
pub fn effective_toml(scene: &Scene) -> Result<String> {
    toml::to_string(scene).map_err(|e| crate::Error::Numerical {
        routine: "scene to TOML".to_string(),
        detail: e.to_string(),
    })
}

/// [`effective_toml`] as a TOML value.
///
/// # Errors
/// As [`effective_toml`].
pub fn effective_value(scene: &Scene) -> Result<Value> {
    Value::try_from(scene).map_err(|e| crate::Error::Numerical {
        routine: "scene to TOML".to_string(),
        detail: e.to_string(),
    })
}

/// The keys a scene uses, defaults included ([`effective_value`]).
///
/// # Errors
/// As [`effective_toml`].
pub fn scene_keys(scene: &Scene) -> Result<Vec<String>> {
    Ok(key_paths(&effective_value(scene)?))
}

/// The documentation of `keys` (concrete paths, [`key_paths`]) as TOML comment lines, so
/// that a scene followed by it is still a valid scene file: the rows of [`KEYS`] that
/// match a key, in the table's order, each as its pattern, `[unit]`, range and default,
/// then its meaning; last, any key without a row.
pub fn document(keys: &[String]) -> String {
    let mut out = String::new();
    for d in KEYS
        .iter()
        .filter(|d| keys.iter().any(|k| matches(d.key, k)))
    {
        out.push_str(&format!(
            "# {}  [{}]  {}; default: {}\n#     {}\n",
            d.key, d.unit, d.range, d.default, d.meaning
        ));
    }
    for k in keys.iter().filter(|k| doc(k).is_none()) {
        out.push_str(&format!("# {k}  (undocumented)\n"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::builtin::BUILTIN;
    use super::*;
    use std::path::Path;

    /// A built-in scene's text as a TOML value.
    fn value_of(text: &str) -> Value {
        text.parse::<toml::Table>().map(Value::Table).expect("TOML")
    }

    /// Every key of every built-in scene, as written and as it will run (defaults
    /// filled in), has a row.
    #[test]
    fn every_key_of_every_builtin_scene_is_documented() {
        for b in BUILTIN {
            let scene = b.load().expect("loads");
            let mut keys = key_paths(&value_of(b.text));
            keys.extend(key_paths(&effective_value(&scene).unwrap()));
            for k in keys {
                assert!(doc(&k).is_some(), "{}: key {k} has no row in KEYS", b.name);
            }
        }
    }

    /// The concrete path of `pattern` in `value` (the first element of an array of
    /// tables, the first budget that has the key), if the scene has the key.
    fn concrete(value: &Value, pattern: &str) -> Option<Vec<String>> {
        fn find(v: &Value, segs: &[&str], acc: &mut Vec<String>) -> bool {
            let Some((first, rest)) = segs.split_first() else {
                return true;
            };
            let (name, array) = match first.strip_suffix("[]") {
                Some(n) => (n, true),
                None => (*first, false),
            };
            let Value::Table(t) = v else { return false };
            let names: Vec<&str> = if name == "<budget>" {
                vec!["quick", "standard", "full"]
            } else {
                vec![name]
            };
            for n in names {
                let Some(child) = t.get(n) else { continue };
                if array {
                    let Value::Array(a) = child else { continue };
                    for (i, e) in a.iter().enumerate() {
                        acc.push(format!("{n}[{i}]"));
                        if find(e, rest, acc) {
                            return true;
                        }
                        acc.pop();
                    }
                } else {
                    acc.push(n.to_string());
                    if find(child, rest, acc) {
                        return true;
                    }
                    acc.pop();
                }
            }
            false
        }
        let segs: Vec<&str> = pattern.split('.').collect();
        let mut acc = Vec::new();
        find(value, &segs, &mut acc).then_some(acc)
    }

    /// Sets the value at `path` (segments such as `runs[0]`, `quick`) in `value`,
    /// creating the last table entry if missing.
    fn set(value: &mut Value, path: &[String], new: Value) {
        let mut v = value;
        for (i, seg) in path.iter().enumerate() {
            let (name, index) = match seg.split_once('[') {
                Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
                None => (seg.as_str(), None),
            };
            let Value::Table(t) = v else {
                panic!("{path:?}: not a table")
            };
            if i + 1 == path.len() && index.is_none() {
                t.insert(name.to_string(), new);
                return;
            }
            let child = t
                .entry(name.to_string())
                .or_insert_with(|| Value::Table(toml::Table::new()));
            v = match index {
                Some(j) => &mut child.as_array_mut().expect("array")[j],
                None => child,
            };
        }
        *v = new;
    }

    /// The error of parsing `value` as a scene, if any.
    fn parse(value: &Value) -> Option<String> {
        let text = toml::to_string(value).expect("to TOML");
        Scene::parse(&text, Path::new("probe.toml"))
            .err()
            .map(|e| e.to_string())
    }

    /// Every row is a key the scene types accept: set in a built-in scene (one with the
    /// key's table, or [compression] keys in a compression scene) to an empty table, the
    /// key is rejected for its type or value, never as an unknown field.
    #[test]
    fn every_documented_key_is_accepted_by_the_scene_types() {
        for d in KEYS {
            let (name, mut value, path) = bases(d.key)
                .into_iter()
                .next()
                .unwrap_or_else(|| panic!("{}: no built-in scene to try it in", d.key));
            set(&mut value, &path, Value::Table(toml::Table::new()));
            let err = parse(&value).unwrap_or_default();
            assert!(
                !err.contains("unknown field"),
                "{} (tried as {} in {name}): {err}",
                d.key,
                path.join(".")
            );
        }
    }

    /// A key that is not a scene key is refused as an unknown field (the probe above can
    /// fail).
    #[test]
    fn an_unknown_key_is_refused_as_unknown() {
        let (_, mut value, mut path) = bases("mesh.elements").remove(0);
        path.pop();
        path.push("no_such_key".to_string());
        set(&mut value, &path, Value::Integer(1));
        let err = parse(&value).expect("refused");
        assert!(err.contains("unknown field"), "{err}");
    }

    /// The built-in scenes to probe the key `pattern` in, as (name, TOML value, the
    /// key's concrete path): those that have it, else those that have its table.
    fn bases(pattern: &str) -> Vec<(&'static str, Value, Vec<String>)> {
        let with = |pattern: &str| -> Vec<(&'static str, Value, Vec<String>)> {
            BUILTIN
                .iter()
                .filter_map(|b| {
                    let v = value_of(b.text);
                    concrete(&v, pattern).map(|p| (b.name, v, p))
                })
                .collect()
        };
        let found = with(pattern);
        if !found.is_empty() {
            return found;
        }
        let Some((parent, leaf)) = pattern.rsplit_once('.') else {
            return found;
        };
        with(parent)
            .into_iter()
            .map(|(n, v, mut p)| {
                p.push(leaf.to_string());
                (n, v, p)
            })
            .collect()
    }

    /// Every row's bounds agree with the validator: in every built-in scene with the key
    /// (or its table), a value just outside each end is refused naming the key; and a
    /// closed end itself is not refused for this key in at least one of them (another
    /// key may then be out of range, such as a burn-in below a two-time point; a mesh
    /// grading other than 1 is refused in a compression scene).
    #[test]
    fn bounds_agree_with_the_validator() {
        let mut probed = 0;
        for d in KEYS {
            let Some(b) = d.bounds else { continue };
            let bases = bases(d.key);
            assert!(!bases.is_empty(), "{}: no built-in scene to probe", d.key);
            let step = |x: f64, up: bool| {
                if b.integer {
                    if up { x + 1.0 } else { x - 1.0 }
                } else if x == 0.0 {
                    if up { 1e-300 } else { -1e-300 }
                } else if up {
                    x + x.abs() * 1e-9
                } else {
                    x - x.abs() * 1e-9
                }
            };
            let outside = [
                if b.lo_open { b.lo } else { step(b.lo, false) },
                if b.hi_open { b.hi } else { step(b.hi, true) },
            ];
            let mut accepted = [b.lo_open, b.hi_open];
            for (name, base, path) in &bases {
                let shown = path.join(".");
                // A list of numbers: probe its first element.
                let number = |x: f64| {
                    let v = if b.integer {
                        Value::Integer(x as i64)
                    } else {
                        Value::Float(x)
                    };
                    match concrete_value(base, path).and_then(Value::as_array) {
                        Some(a) => {
                            let mut a = a.clone();
                            a[0] = v;
                            Value::Array(a)
                        }
                        None => v,
                    }
                };
                let refusal = |x: f64| {
                    let mut v = base.clone();
                    set(&mut v, path, number(x));
                    parse(&v)
                };
                for x in outside {
                    let err = refusal(x).unwrap_or_else(|| {
                        panic!("{name}: {shown} = {x:e} accepted, the row says {}", d.range)
                    });
                    // A type error (a negative count) is named by the parser, which
                    // writes an element of an array of tables without its index.
                    let unindexed: Vec<&str> =
                        path.iter().map(|s| s.split('[').next().unwrap()).collect();
                    assert!(
                        err.contains(&format!("key `{shown}"))
                            || err.contains(&format!("key `{}`", unindexed.join("."))),
                        "{name}: {shown} = {x:e}: {err}"
                    );
                    probed += 1;
                }
                for (end, x) in [b.lo, b.hi].into_iter().enumerate() {
                    let named = refusal(x).is_some_and(|e| e.contains(&format!("key `{shown}")));
                    accepted[end] |= !named;
                }
            }
            assert!(
                accepted.iter().all(|a| *a),
                "{}: a closed end of {:?} is refused in every scene, the row says {}",
                d.key,
                (b.lo, b.hi),
                d.range
            );
        }
        assert!(probed >= 40, "only {probed} probes");
    }

    /// The value at a concrete path.
    fn concrete_value<'a>(value: &'a Value, path: &[String]) -> Option<&'a Value> {
        let mut v = value;
        for seg in path {
            let (name, index) = match seg.split_once('[') {
                Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
                None => (seg.as_str(), None),
            };
            v = v.get(name)?;
            if let Some(j) = index {
                v = v.get(j)?;
            }
        }
        Some(v)
    }

    /// The scene as it will run reads back as the same scene (what `scene show` prints
    /// can be saved and run).
    #[test]
    fn effective_scene_reads_back() {
        for b in BUILTIN {
            let scene = b.load().unwrap();
            let text = toml::to_string(&effective_value(&scene).unwrap()).unwrap();
            let again = Scene::parse_named(&text, Path::new("x"), b.name)
                .unwrap_or_else(|e| panic!("{}: {e}\n{text}", b.name));
            assert_eq!(
                toml::to_string(&again).unwrap(),
                toml::to_string(&scene).unwrap(),
                "{}",
                b.name
            );
        }
    }

    #[test]
    fn patterns_match_budgets_and_arrays() {
        assert!(matches(
            "runs[].<budget>.duration_tau1",
            "runs[].standard.duration_tau1"
        ));
        assert!(!matches(
            "runs[].<budget>.duration_tau1",
            "runs[].other.duration_tau1"
        ));
        assert!(!matches("mesh.elements", "mesh.elements.x"));
        let v = value_of("a = 1\n[[r]]\nb = 2\nq = { c = 3 }\n[[r]]\nb = 4\n");
        assert_eq!(key_paths(&v), ["a", "r[].b", "r[].q.c"]);
    }
}
