//! The column dictionary: the unit and meaning of every column of every CSV table the
//! commands write (issue #13). Each report directory's journal carries, per CSV file
//! written, its columns with their units ([`super::Manifest::columns`], filled by
//! [`super::ReportRun::write`] from the header line through [`table_schema`]); the
//! column contents themselves are never changed.
//!
//! A column's meaning depends on its table (`std_error` is a variance in a profile, a
//! force ratio in a force–strain table), so the dictionary is one list of columns per
//! kind of table ([`TABLES`]), a table kind being recognized by how the file name ends.
//!
//! ## Units
//! Written in the scene's base dimensions, which the provenance of the scene maps to
//! concrete units ([`super::provenance::SceneProvenance::units`]: µm, pN·µm, s for a
//! scene given in physical units):
//!
//! | unit | meaning |
//! |---|---|
//! | `[L]`, `[L]^2` | scene length (the unit of `filament.length`), its square |
//! | `1/[L]` | an inverse length (a wavenumber) |
//! | `[T]`, `1/[T]` | scene time (the unit that ξ, L and EI imply; τ₁ is given in it): physical time, *not* a multiple of τ₁ |
//! | `[L]^2*[T]` | a power spectral density of a length (one-sided, per unit of frequency) |
//! | `tau1` | a multiple of τ₁ = ξL⁴/(π⁴EI) |
//! | `F_c0`, `eps_c0` | a multiple of the Euler load π²EI/L² or of the Euler strain π²EI/(EA·L²) |
//! | `1` | a dimensionless number (a ratio, a z-score, a p-value, a mode number) |
//! | `count` | a whole number of things (elements, trajectories, steps, modes) |
//! | `s` | wall-clock seconds of the computer (not simulated time) |
//! | `text` | a name or a note |
//! | `unit of observable` | the unit of the row's `observable` (see that column) |

use serde::{Deserialize, Serialize};

/// One column of a table kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    /// The header name; a name ending in `#` stands for that prefix followed by a number
    /// (`mode#`: `mode1`, `mode2`, …).
    pub name: &'static str,
    /// The unit (see the [module docs](self)).
    pub unit: &'static str,
    /// What the column holds.
    pub meaning: &'static str,
}

/// A kind of CSV table: the files whose name ends with `suffix`, and their columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableKind {
    /// How the file name ends (the first kind in [`TABLES`] that matches is used).
    pub suffix: &'static str,
    /// What the table holds.
    pub meaning: &'static str,
    /// Its columns.
    pub columns: &'static [Column],
}

const fn col(name: &'static str, unit: &'static str, meaning: &'static str) -> Column {
    Column {
        name,
        unit,
        meaning,
    }
}

/// A membrane's mode in the per-mode tables of `verify` (after `mode`): its lattice
/// indices m, n and wavenumber |q| (a filament's tables have no such columns).
const MODE_M: Column = col("m", "1", "membrane only: lattice index of the mode along x");
/// See [`MODE_M`].
const MODE_N: Column = col("n", "1", "membrane only: lattice index of the mode along y");
/// See [`MODE_M`].
const MODE_Q: Column = col("q", "1/[L]", "membrane only: wavenumber |q| of the mode");

/// Every kind of CSV table `verify`, `converge`, `stability`, `work-precision` and
/// `calibrate` write.
pub const TABLES: &[TableKind] = &[
    TableKind {
        suffix: "-mode-statistics.csv",
        meaning: "verify, linear scene, per run: stationary variance and relaxation rate of each checked mode (modal amplitude a_n, w = sum a_n phi_n(x), phi_n -> sin(n pi x/L))",
        columns: &[
            col("mode", "1", "mode number n"),
            MODE_M,
            MODE_N,
            MODE_Q,
            col("variance", "[L]^2", "simulated stationary variance of a_n"),
            col("variance_std_error", "[L]^2", "its standard error"),
            col(
                "variance_discrete",
                "[L]^2",
                "exact variance of the discretized system and integrator",
            ),
            col(
                "variance_continuum",
                "[L]^2",
                "continuum variance 2kT L^3/(pi^4 n^4 EI)",
            ),
            col(
                "rate",
                "1/[T]",
                "simulated autocorrelation decay rate of a_n",
            ),
            col("rate_std_error", "1/[T]", "its standard error"),
            col(
                "rate_discrete",
                "1/[T]",
                "exact discrete rate -ln(m)/dt (m: one-step multiplier)",
            ),
            col(
                "rate_continuum",
                "1/[T]",
                "continuum rate pi^4 n^4 EI/(xi L^4)",
            ),
        ],
    },
    TableKind {
        suffix: "-modes.csv",
        meaning: "verify, linear scene, per run: modal variance relative to equipartition kT/lambda_i of the discrete modes",
        columns: &[
            col("mode", "1", "mode number n"),
            MODE_M,
            MODE_N,
            MODE_Q,
            col(
                "predicted_ratio",
                "1",
                "exact discrete variance / equipartition",
            ),
            col("simulated_ratio", "1", "simulated variance / equipartition"),
            col("std_error", "1", "standard error of simulated_ratio"),
        ],
    },
    TableKind {
        suffix: "-profile.csv",
        meaning: "verify, linear scene, per run: equilibrium profile <w^2(x)>",
        columns: &[
            col("x", "[L]", "position along the filament"),
            col("variance", "[L]^2", "simulated <w^2(x)>"),
            col("std_error", "[L]^2", "its standard error"),
            col(
                "discrete",
                "[L]^2",
                "exact <w^2(x)> of the discretized system",
            ),
            col(
                "continuum",
                "[L]^2",
                "continuum <w^2(x)> (eq. 4, t -> infinity)",
            ),
        ],
    },
    TableKind {
        suffix: "-two-time.csv",
        meaning: "verify, linear scene, per run: two-time correlation <w(x,t) w(y,eta)> from rest (eq. 4)",
        columns: &[
            col("x", "[L]", "first position"),
            col("y", "[L]", "second position"),
            col(
                "t",
                "[T]",
                "earlier time since the start from rest (scene time; the scene file gives it in tau1)",
            ),
            col(
                "eta",
                "[T]",
                "later time since the start from rest (scene time)",
            ),
            col("correlation", "[L]^2", "simulated <w(x,t) w(y,eta)>"),
            col("std_error", "[L]^2", "its standard error"),
            col(
                "discrete",
                "[L]^2",
                "exact value for the discretized system",
            ),
            col("continuum", "[L]^2", "continuum value, eq. (4)"),
        ],
    },
    TableKind {
        suffix: "-spectrum.csv",
        meaning: "verify, linear scene, per run: one-sided power spectral density of modal amplitudes (Welch)",
        columns: &[
            col("mode", "1", "mode number n"),
            col(
                "frequency",
                "1/[T]",
                "frequency (cycles per scene time unit)",
            ),
            col("psd", "[L]^2*[T]", "simulated one-sided PSD of a_n"),
            col(
                "expected",
                "[L]^2*[T]",
                "its exact expectation (sampled AR(1) spectrum, Welch window included)",
            ),
        ],
    },
    TableKind {
        suffix: "element-uniform-vs-elements.csv",
        meaning: "verify, fem scene with element-uniform noise: stationary modal variance of the paper's noise (eq. 5) relative to equipartition, against element count (theory)",
        columns: &[
            col("elements", "count", "elements of the uniform mesh"),
            col("mode#", "1", "variance of mode # / equipartition"),
        ],
    },
    TableKind {
        suffix: "force-strain.csv",
        meaning: "verify, compression scene, per run: mean compressive force against imposed strain (Fig. 2)",
        columns: &[
            col("strain_ratio", "eps_c0", "imposed strain eps/eps_c0"),
            col("force_ratio", "F_c0", "simulated <F>/F_c0"),
            col("std_error", "F_c0", "its standard error"),
            col(
                "theory_discrete",
                "F_c0",
                "exact equilibrium <F>/F_c0 of the discretized filament",
            ),
            col(
                "theory_continuum",
                "F_c0",
                "exact equilibrium <F>/F_c0 of the continuum",
            ),
        ],
    },
    TableKind {
        suffix: "stability-cells.csv",
        meaning: "stability: one line per cell (integrator x elements x dt lambda_max)",
        columns: &[
            col("integrator", "text", "time integrator"),
            col("elements", "count", "element count"),
            col(
                "dt_lambda_max",
                "1",
                "time step times the largest generalized eigenvalue",
            ),
            col("dt_tau1", "tau1", "time step"),
            col(
                "max_multiplier",
                "1",
                "largest |one-step multiplier| over the modes",
            ),
            col("status", "text", "stable, biased, unstable, ..."),
            col("checked_modes", "count", "modes whose bias was tested"),
            col(
                "unresolved_modes",
                "count",
                "modes too fast to resolve at this step",
            ),
            col(
                "predicted_max_bias",
                "1",
                "largest predicted relative stationary-variance bias",
            ),
            col(
                "diverged_at",
                "count",
                "step at which the run diverged (empty: it did not)",
            ),
            col("detail", "text", "what was found"),
        ],
    },
    TableKind {
        suffix: "stationary-bias.csv",
        meaning: "stability: one line per checked mode of every cell: measured stationary variance against the integrator's exact discrete-time formula",
        columns: &[
            col("integrator", "text", "time integrator"),
            col("elements", "count", "element count"),
            col(
                "dt_lambda_max",
                "1",
                "time step times the largest generalized eigenvalue",
            ),
            col("mode", "1", "mode number"),
            col("lambda_dt", "1", "the mode's rate times the time step"),
            col("multiplier", "1", "one-step multiplier of the mode"),
            col("measured_ratio", "1", "measured variance / kT lambda^-1"),
            col("std_error", "1", "its standard error"),
            col(
                "formula_ratio",
                "1",
                "the integrator's exact discrete-time ratio",
            ),
            col("z_formula", "1", "z-score of measured against formula"),
            col("p_formula", "1", "its p-value"),
            col(
                "formula_rejected",
                "text",
                "whether Holm rejects the formula (true/false)",
            ),
            col("z_bias", "1", "z-score of measured against 1 (no bias)"),
            col("p_bias", "1", "its p-value"),
        ],
    },
    TableKind {
        suffix: "work-precision.csv",
        meaning: "work-precision: one line per method and time step: error in <w^2(L/2)> against wall time",
        columns: &[
            col("integrator", "text", "time integrator"),
            col("noise", "text", "noise model"),
            col("dt_tau1", "tau1", "time step"),
            col("trajectories", "count", "independent trajectories"),
            col("duration_tau1", "tau1", "sampled duration per trajectory"),
            col(
                "steps_per_trajectory",
                "count",
                "sampled steps per trajectory",
            ),
            col("wall_seconds", "s", "wall time of the ensemble"),
            col("estimate", "[L]^2", "simulated <w^2(L/2)>"),
            col("std_error", "[L]^2", "its standard error"),
            col(
                "discrete",
                "[L]^2",
                "exact <w^2(L/2)> of the discrete system and integrator",
            ),
            col("continuum", "[L]^2", "continuum <w^2(L/2)>"),
            col("rel_error", "1", "(estimate - continuum)/continuum"),
            col("rel_std_error", "1", "std_error/continuum"),
            col("rel_bias", "1", "(discrete - continuum)/continuum"),
            col("z_discrete", "1", "(estimate - discrete)/std_error"),
            col(
                "seconds_to_tolerance",
                "s",
                "projected wall time to reach the tolerance (empty: never)",
            ),
        ],
    },
    TableKind {
        suffix: "p-values.csv",
        meaning: "calibrate: one line per check per seed: its raw and Holm-adjusted p-values",
        columns: &[
            col("scene", "text", "scene name"),
            col(
                "seed",
                "1",
                "master seed of the scene's run (verify --seed)",
            ),
            col("check", "text", "check name, unique within the scene"),
            col(
                "kind",
                "text",
                "check kind (z-test, ks, chi2-variance, ...)",
            ),
            col("p_value", "1", "raw p-value (empty: the check has none)"),
            col(
                "p_adjusted",
                "1",
                "Holm-adjusted p-value within the scene at that seed",
            ),
            col(
                "passed",
                "text",
                "true or false, at the family-wise level alpha",
            ),
        ],
    },
    TableKind {
        suffix: "-elements.csv",
        meaning: "converge --over elements: one line per element count and observable",
        columns: CONVERGE_ELEMENTS,
    },
    TableKind {
        suffix: "-dt.csv",
        meaning: "converge --over dt: one line per time step and observable",
        columns: CONVERGE_DT,
    },
];

/// Columns of `converge --over elements`.
const CONVERGE_ELEMENTS: &[Column] = &[
    col("value", "count", "element count"),
    col("h", "[L]", "element length L/elements"),
    col(
        "observable",
        "text",
        "what is measured: profile<w^2(x/L)> and mode# ([L]^2), force ratios (F_c0)",
    ),
    col("estimate", "unit of observable", "simulated value"),
    col("std_error", "unit of observable", "its standard error"),
    col(
        "discrete",
        "unit of observable",
        "exact value for this discretization (empty: none)",
    ),
    col(
        "limit",
        "unit of observable",
        "the reference the error is measured against",
    ),
    col("total_error", "unit of observable", "|estimate - limit|"),
    col("total_error_se", "unit of observable", "its standard error"),
    col(
        "exact_error",
        "unit of observable",
        "|discrete - limit| (empty: none)",
    ),
    col("status", "text", "resolved or sampling floor"),
];

/// Columns of `converge --over dt`.
const CONVERGE_DT: &[Column] = &[
    col("value", "tau1", "time step"),
    col("h", "tau1", "time step dt/tau1"),
    CONVERGE_ELEMENTS[2],
    CONVERGE_ELEMENTS[3],
    CONVERGE_ELEMENTS[4],
    CONVERGE_ELEMENTS[5],
    CONVERGE_ELEMENTS[6],
    CONVERGE_ELEMENTS[7],
    CONVERGE_ELEMENTS[8],
    CONVERGE_ELEMENTS[9],
    CONVERGE_ELEMENTS[10],
];

/// One column of a written table, as its schema records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnSchema {
    /// The header name.
    pub name: String,
    /// Its unit; `null` for a column the dictionary does not know.
    pub unit: Option<String>,
    /// What it holds.
    pub meaning: String,
}

/// The schema of one written CSV file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableSchema {
    /// What the table holds (`null`: a file the dictionary does not know).
    pub table: Option<String>,
    /// Its columns, in file order.
    pub columns: Vec<ColumnSchema>,
}

impl TableSchema {
    /// The header names the dictionary does not know.
    pub fn unknown(&self) -> Vec<&str> {
        self.columns
            .iter()
            .filter(|c| c.unit.is_none())
            .map(|c| c.name.as_str())
            .collect()
    }
}

/// The table kind of a file named `file_name` (its last path component is used).
pub fn table_kind(file_name: &str) -> Option<&'static TableKind> {
    let name = file_name.rsplit(['/', '\\']).next().unwrap_or(file_name);
    TABLES.iter().find(|t| name.ends_with(t.suffix))
}

/// The dictionary entry of column `name` in `kind`.
pub fn column(kind: &TableKind, name: &str) -> Option<&'static Column> {
    kind.columns
        .iter()
        .find(|c| match c.name.strip_suffix('#') {
            Some(prefix) => name
                .strip_prefix(prefix)
                .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit())),
            None => c.name == name,
        })
}

/// The schema of the CSV file `file_name` whose header line is `header` (names separated
/// by commas): each column with its unit and meaning from the dictionary.
pub fn table_schema(file_name: &str, header: &str) -> TableSchema {
    let kind = table_kind(file_name);
    let columns = header
        .trim_end_matches(['\r', '\n'])
        .split(',')
        .map(|name| {
            let name = name.trim();
            let known = kind.and_then(|k| column(k, name));
            ColumnSchema {
                name: name.to_string(),
                unit: known.map(|c| c.unit.to_string()),
                meaning: known.map_or_else(
                    || "not in the column dictionary".to_string(),
                    |c| c.meaning.replace('#', "n"),
                ),
            }
        })
        .collect();
    TableSchema {
        table: kind.map(|k| k.meaning.to_string()),
        columns,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_find_their_table_kind() {
        let kind = |f: &str| table_kind(f).map(|k| k.suffix);
        assert_eq!(kind("s/cn-modes.csv"), Some("-modes.csv"));
        assert_eq!(
            kind("s/cn-mode-statistics.csv"),
            Some("-mode-statistics.csv")
        );
        assert_eq!(
            kind("s/element-uniform-vs-elements.csv"),
            Some("element-uniform-vs-elements.csv")
        );
        assert_eq!(
            kind("compression-2d-metropolis-elements.csv"),
            Some("-elements.csv")
        );
        assert_eq!(kind("hinged-linear-2d-cn-dt.csv"), Some("-dt.csv"));
        assert_eq!(
            kind("s/metropolis-half-force-strain.csv"),
            Some("force-strain.csv")
        );
        assert_eq!(kind("s/other.csv"), None);
    }

    #[test]
    fn headers_get_units_and_unknown_columns_are_named() {
        let s = table_schema(
            "s/cn-two-time.csv",
            "x,y,t,eta,correlation,std_error,discrete,continuum\n",
        );
        assert!(s.unknown().is_empty());
        assert_eq!(s.columns[2].unit.as_deref(), Some("[T]"));
        let s = table_schema(
            "s/element-uniform-vs-elements.csv",
            "elements,mode1,mode12,mode,modex",
        );
        assert_eq!(s.unknown(), ["mode", "modex"]);
        assert_eq!(s.columns[2].meaning, "variance of mode n / equipartition");
        assert_eq!(table_schema("x.csv", "a").unknown(), ["a"]);
    }

    /// Every table kind names each column once, with a unit from the documented list.
    #[test]
    fn the_dictionary_is_well_formed() {
        let units = [
            "[L]",
            "[L]^2",
            "1/[L]",
            "[T]",
            "1/[T]",
            "[L]^2*[T]",
            "tau1",
            "F_c0",
            "eps_c0",
            "1",
            "count",
            "s",
            "text",
            "unit of observable",
        ];
        for t in TABLES {
            for (i, c) in t.columns.iter().enumerate() {
                assert!(
                    units.contains(&c.unit),
                    "{} {}: {}",
                    t.suffix,
                    c.name,
                    c.unit
                );
                assert!(!c.meaning.is_empty());
                assert!(
                    t.columns[..i].iter().all(|d| d.name != c.name),
                    "{} repeats {}",
                    t.suffix,
                    c.name
                );
            }
        }
    }
}
