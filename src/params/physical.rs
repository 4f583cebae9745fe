//! A filament in physical units (issue #13): the `[filament]` keys of a scene that give a
//! real filament — contour length, persistence length or bending rigidity, solvent
//! viscosity or drag per length, temperature — and their conversion to the consistent
//! units the simulation uses: **µm, s, pN** (so energies in pN·µm, EI in pN·µm², EA in
//! pN, ξ in pN·s/µm²).
//!
//! ```toml
//! [filament]                      # actin in water at 300 K
//! contour_length_um = 10.0        # L
//! persistence_length_um = 17.0    # ℓp (or bending_rigidity_pn_um2 = EI)
//! viscosity_pa_s = 1.0e-3         # η (or drag_pn_s_per_um2 = ξ)
//! diameter_nm = 7.0               # d, with viscosity_pa_s only
//! temperature_k = 300.0           # T
//! stretch_rigidity_pn = 4.4e4     # EA (optional)
//! ```
//!
//! The conversion ([`PhysicalFilament::to_consistent`], the one place it happens):
//!
//! - L = `contour_length_um` µm;
//! - kT = k_B·T with k_B = 1.380649 × 10⁻²³ J/K = 1.380649 × 10⁻⁵ pN·µm/K (1 pN·µm =
//!   10⁻¹⁸ J; exact in the 2019 SI): 4.142 × 10⁻³ pN·µm = 4.142 pN·nm at 300 K;
//! - EI = `bending_rigidity_pn_um2`, or EI = ℓp·kT (ℓp = EI/kT, the persistence length
//!   of a filament in 3D; ℓp/L is the scene's [`FilamentParams::persistence_ratio`]);
//! - ξ = `drag_pn_s_per_um2`, or the slender-body drag per length of a rod of length L
//!   and diameter d moving perpendicular to its axis,
//!   ξ⊥ = 4πη / (ln(L/d) + ½),
//!   leading orders of the expansion in 1/ln(L/d) of slender-body theory (R. G. Cox,
//!   *The motion of long slender bodies in a viscous fluid. Part 1. General theory*,
//!   J. Fluid Mech. 44, 791 (1970)); the O(1) constant depends on the shape of the
//!   ends, so ξ is known to a few per cent at L/d ~ 10³. η in Pa·s equals η in
//!   pN·s/µm² (1 Pa·s = 10¹² pN·s / 10¹² µm²); d = `diameter_nm`·10⁻³ µm. Slender-body
//!   theory needs L ≫ d: L/d ≥ [`MIN_SLENDERNESS`] is required;
//! - EA = `stretch_rigidity_pn`, or, if not given, EA = 10⁶·kT/L: the same EA·L/kT =
//!   10⁶ as the consistent default (EA matters only to compression scenes).
//!
//! A `[filament]` table is either wholly physical or wholly consistent (`length`,
//! `bending_rigidity`, `stretch_rigidity`, `drag`, `kt`); mixing the two, or giving
//! both ℓp and EI, or both η and ξ, is refused naming the keys ([`FilamentInput::resolve`]).
//! The scene validator's ranges apply to the converted values, and its messages name
//! the physical keys the user wrote ([`PhysicalFilament::keys_of`]).

use super::FilamentParams;
use crate::output::provenance::{ParameterRecord, Quantity};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// Boltzmann's constant in pN·µm/K (1.380649 × 10⁻²³ J/K exactly, 1 pN·µm = 10⁻¹⁸ J).
pub const BOLTZMANN_PN_UM_PER_K: f64 = 1.380649e-5;

/// Smallest contour length over diameter for the slender-body drag.
pub const MIN_SLENDERNESS: f64 = 10.0;

/// EA·L/kT when a physical filament does not give `stretch_rigidity_pn` (the consistent
/// default's ratio).
pub const DEFAULT_STRETCH_RATIO: f64 = 1.0e6;

/// The consistent keys of `[filament]`.
pub const CONSISTENT_KEYS: [&str; 5] = [
    "length",
    "bending_rigidity",
    "stretch_rigidity",
    "drag",
    "kt",
];

/// The `[filament]` table as written: consistent or physical keys (see the
/// [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilamentInput {
    /// Length L (consistent units).
    pub length: Option<f64>,
    /// Bending rigidity EI (consistent units).
    pub bending_rigidity: Option<f64>,
    /// Stretching rigidity EA (consistent units).
    pub stretch_rigidity: Option<f64>,
    /// Drag per length ξ (consistent units).
    pub drag: Option<f64>,
    /// Thermal energy kT (consistent units).
    pub kt: Option<f64>,
    /// Contour length L in µm.
    pub contour_length_um: Option<f64>,
    /// Persistence length ℓp = EI/kT in µm.
    pub persistence_length_um: Option<f64>,
    /// Bending rigidity EI in pN·µm².
    pub bending_rigidity_pn_um2: Option<f64>,
    /// Stretching rigidity EA in pN.
    pub stretch_rigidity_pn: Option<f64>,
    /// Drag per length ξ in pN·s/µm².
    pub drag_pn_s_per_um2: Option<f64>,
    /// Solvent viscosity η in Pa·s (with `diameter_nm`).
    pub viscosity_pa_s: Option<f64>,
    /// Filament diameter d in nm (with `viscosity_pa_s`).
    pub diameter_nm: Option<f64>,
    /// Temperature T in K.
    pub temperature_k: Option<f64>,
    /// The ends, `"<left>-<right>"` ([`crate::params::Ends`]; default both hinged). Not a
    /// parameter of [`FilamentParams`]: the scene reads it ([`crate::scene::Scene::ends`]).
    pub ends: Option<crate::params::Ends>,
}

/// How a physical filament gives its bending stiffness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stiffness {
    /// Persistence length ℓp in µm.
    PersistenceLength(f64),
    /// Bending rigidity EI in pN·µm².
    BendingRigidity(f64),
}

/// How a physical filament gives its drag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drag {
    /// Drag per length ξ in pN·s/µm².
    PerLength(f64),
    /// Solvent viscosity η in Pa·s and filament diameter d in nm (slender-body drag).
    Solvent {
        /// η in Pa·s.
        viscosity_pa_s: f64,
        /// d in nm.
        diameter_nm: f64,
    },
}

/// A filament given in physical units (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalFilament {
    /// L in µm.
    pub contour_length_um: f64,
    /// ℓp or EI.
    pub stiffness: Stiffness,
    /// EA in pN, if given.
    pub stretch_rigidity_pn: Option<f64>,
    /// ξ, or η and d.
    pub drag: Drag,
    /// T in K.
    pub temperature_k: f64,
}

/// A `[filament]` table that mixes or leaves out keys: the keys concerned and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FilamentKeyError {
    /// The keys the message is about, as written in `[filament]`.
    pub keys: Vec<&'static str>,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl std::fmt::Display for FilamentKeyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl FilamentInput {
    /// The keys given, consistent then physical, as written.
    fn given(&self) -> (Vec<&'static str>, Vec<&'static str>) {
        let consistent = [
            ("length", self.length),
            ("bending_rigidity", self.bending_rigidity),
            ("stretch_rigidity", self.stretch_rigidity),
            ("drag", self.drag),
            ("kt", self.kt),
        ];
        let physical = [
            ("contour_length_um", self.contour_length_um),
            ("persistence_length_um", self.persistence_length_um),
            ("bending_rigidity_pn_um2", self.bending_rigidity_pn_um2),
            ("stretch_rigidity_pn", self.stretch_rigidity_pn),
            ("drag_pn_s_per_um2", self.drag_pn_s_per_um2),
            ("viscosity_pa_s", self.viscosity_pa_s),
            ("diameter_nm", self.diameter_nm),
            ("temperature_k", self.temperature_k),
        ];
        let names = |list: &[(&'static str, Option<f64>)]| {
            list.iter()
                .filter(|(_, v)| v.is_some())
                .map(|(k, _)| *k)
                .collect()
        };
        (names(&consistent), names(&physical))
    }

    /// The parameters the simulation uses, and the physical filament if the table gave
    /// one. A consistent table takes the [`FilamentParams::default`] of every key left
    /// out.
    ///
    /// # Errors
    /// [`FilamentKeyError`] naming the keys: consistent and physical keys mixed, both
    /// `persistence_length_um` and `bending_rigidity_pn_um2`, both `viscosity_pa_s` and
    /// `drag_pn_s_per_um2`, `viscosity_pa_s` without `diameter_nm` or the reverse, or a
    /// required physical key left out.
    pub fn resolve(&self) -> Result<(FilamentParams, Option<PhysicalFilament>), FilamentKeyError> {
        let (consistent, physical) = self.given();
        if physical.is_empty() {
            let d = FilamentParams::default();
            let params = FilamentParams {
                length: self.length.unwrap_or(d.length),
                bending_rigidity: self.bending_rigidity.unwrap_or(d.bending_rigidity),
                stretch_rigidity: self.stretch_rigidity.unwrap_or(d.stretch_rigidity),
                drag: self.drag.unwrap_or(d.drag),
                kt: self.kt.unwrap_or(d.kt),
            };
            return Ok((params, None));
        }
        let quote = |keys: &[&str]| {
            keys.iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        if !consistent.is_empty() {
            let mut keys = physical.clone();
            keys.extend(&consistent);
            return Err(FilamentKeyError {
                message: format!(
                    "mixes physical keys ({}) with consistent keys ({}): give the filament either in physical units (contour_length_um, persistence_length_um or bending_rigidity_pn_um2, viscosity_pa_s and diameter_nm or drag_pn_s_per_um2, temperature_k, optional stretch_rigidity_pn) or in consistent units (length, bending_rigidity, stretch_rigidity, drag, kt), not both",
                    quote(&physical),
                    quote(&consistent)
                ),
                keys,
            });
        }
        let both = |a: &'static str, b: &'static str, what: &str| FilamentKeyError {
            keys: vec![a, b],
            message: format!("gives both `{a}` and `{b}`: give one of them ({what})"),
        };
        let neither = |a: &'static str, b: &'static str, what: &str| FilamentKeyError {
            keys: vec![a, b],
            message: format!(
                "a filament in physical units needs `{a}` or `{b}` ({what}); given: {}",
                quote(&physical)
            ),
        };
        let required = |key: &'static str, v: Option<f64>, what: &str| {
            v.ok_or_else(|| FilamentKeyError {
                keys: vec![key],
                message: format!(
                    "a filament in physical units needs `{key}` ({what}); given: {}",
                    quote(&physical)
                ),
            })
        };
        let contour_length_um = required("contour_length_um", self.contour_length_um, "L in µm")?;
        let temperature_k = required("temperature_k", self.temperature_k, "T in K")?;
        let (lp, ei) = ("persistence_length_um", "bending_rigidity_pn_um2");
        let stiffness_what = "lp = EI/kT in µm, or EI in pN·µm²";
        let stiffness = match (self.persistence_length_um, self.bending_rigidity_pn_um2) {
            (Some(_), Some(_)) => return Err(both(lp, ei, stiffness_what)),
            (Some(v), None) => Stiffness::PersistenceLength(v),
            (None, Some(v)) => Stiffness::BendingRigidity(v),
            (None, None) => return Err(neither(lp, ei, stiffness_what)),
        };
        let (eta, xi) = ("viscosity_pa_s", "drag_pn_s_per_um2");
        let drag_what =
            "the solvent viscosity in Pa·s with diameter_nm, or the drag per length in pN·s/µm²";
        let drag = match (
            self.viscosity_pa_s,
            self.drag_pn_s_per_um2,
            self.diameter_nm,
        ) {
            (Some(_), Some(_), _) => return Err(both(eta, xi, drag_what)),
            (None, None, _) => return Err(neither(eta, xi, drag_what)),
            (Some(viscosity_pa_s), None, Some(diameter_nm)) => Drag::Solvent {
                viscosity_pa_s,
                diameter_nm,
            },
            (Some(_), None, None) => {
                return Err(FilamentKeyError {
                    keys: vec!["diameter_nm", "viscosity_pa_s"],
                    message: "gives `viscosity_pa_s` without `diameter_nm`: the slender-body drag 4 pi eta/(ln(L/d) + 1/2) needs the filament diameter d in nm".to_string(),
                });
            }
            (None, Some(_), Some(_)) => {
                return Err(FilamentKeyError {
                    keys: vec!["diameter_nm", "drag_pn_s_per_um2"],
                    message: "gives `diameter_nm` with `drag_pn_s_per_um2`: the diameter is used only with `viscosity_pa_s` (the slender-body drag); leave it out or give the viscosity instead of the drag".to_string(),
                });
            }
            (None, Some(v), None) => Drag::PerLength(v),
        };
        let filament = PhysicalFilament {
            contour_length_um,
            stiffness,
            stretch_rigidity_pn: self.stretch_rigidity_pn,
            drag,
            temperature_k,
        };
        Ok((filament.to_consistent(), Some(filament)))
    }
}

/// The slender-body drag per length of a rod of length `length` and diameter `diameter`
/// (same unit) in a solvent of viscosity `viscosity`: ξ⊥ = 4πη/(ln(L/d) + ½) (see the
/// [module docs](self)), in the unit of `viscosity` (Pa·s = pN·s/µm²).
pub fn slender_body_drag(viscosity: f64, length: f64, diameter: f64) -> f64 {
    4.0 * PI * viscosity / ((length / diameter).ln() + 0.5)
}

impl PhysicalFilament {
    /// The thermal energy kT in pN·µm.
    pub fn kt(&self) -> f64 {
        BOLTZMANN_PN_UM_PER_K * self.temperature_k
    }

    /// The filament in the consistent units µm, s, pN: the one conversion (see the
    /// [module docs](self)). Not validated: the scene validator checks the result.
    pub fn to_consistent(&self) -> FilamentParams {
        let length = self.contour_length_um;
        let kt = self.kt();
        let bending_rigidity = match self.stiffness {
            Stiffness::PersistenceLength(lp) => lp * kt,
            Stiffness::BendingRigidity(ei) => ei,
        };
        let drag = match self.drag {
            Drag::PerLength(xi) => xi,
            Drag::Solvent {
                viscosity_pa_s,
                diameter_nm,
            } => slender_body_drag(viscosity_pa_s, length, diameter_nm * 1e-3),
        };
        FilamentParams {
            length,
            bending_rigidity,
            stretch_rigidity: self
                .stretch_rigidity_pn
                .unwrap_or(DEFAULT_STRETCH_RATIO * kt / length),
            drag,
            kt,
        }
    }

    /// The physical keys that consistent parameter `param` (a [`CONSISTENT_KEYS`] entry)
    /// was converted from, as written in `[filament]`.
    pub fn keys_of(&self, param: &str) -> Vec<&'static str> {
        match param {
            "length" => vec!["contour_length_um"],
            "kt" => vec!["temperature_k"],
            "bending_rigidity" => match self.stiffness {
                Stiffness::PersistenceLength(_) => vec!["persistence_length_um", "temperature_k"],
                Stiffness::BendingRigidity(_) => vec!["bending_rigidity_pn_um2"],
            },
            "drag" => match self.drag {
                Drag::PerLength(_) => vec!["drag_pn_s_per_um2"],
                Drag::Solvent { .. } => vec!["viscosity_pa_s", "diameter_nm", "contour_length_um"],
            },
            "stretch_rigidity" => match self.stretch_rigidity_pn {
                Some(_) => vec!["stretch_rigidity_pn"],
                None => vec!["contour_length_um", "temperature_k"],
            },
            _ => Vec::new(),
        }
    }

    /// The keys as written with their values and units, in table order.
    pub fn given(&self) -> Vec<(&'static str, f64, &'static str)> {
        let mut given = vec![("contour_length_um", self.contour_length_um, "µm")];
        given.push(match self.stiffness {
            Stiffness::PersistenceLength(lp) => ("persistence_length_um", lp, "µm"),
            Stiffness::BendingRigidity(ei) => ("bending_rigidity_pn_um2", ei, "pN·µm²"),
        });
        if let Some(ea) = self.stretch_rigidity_pn {
            given.push(("stretch_rigidity_pn", ea, "pN"));
        }
        match self.drag {
            Drag::PerLength(xi) => given.push(("drag_pn_s_per_um2", xi, "pN·s/µm²")),
            Drag::Solvent {
                viscosity_pa_s,
                diameter_nm,
            } => {
                given.push(("viscosity_pa_s", viscosity_pa_s, "Pa·s"));
                given.push(("diameter_nm", diameter_nm, "nm"));
            }
        }
        given.push(("temperature_k", self.temperature_k, "K"));
        given
    }
}

/// The units of the consistent parameters: concrete for a physical filament, in the
/// scene's base dimensions `[L]`, `[E]`, `[T]` otherwise. Order: length,
/// bending_rigidity, stretch_rigidity, drag, kt, time, force.
fn units(physical: bool) -> [&'static str; 7] {
    if physical {
        ["µm", "pN·µm²", "pN", "pN·s/µm²", "pN·µm", "s", "pN"]
    } else {
        [
            "[L]",
            "[E]*[L]",
            "[E]/[L]",
            "[E]*[T]/[L]^3",
            "[E]",
            "[T]",
            "[E]/[L]",
        ]
    }
}

/// The base dimensions `[L]`, `[E]`, `[T]` of a scene and their concrete units.
pub fn base_units(physical: bool) -> BTreeMap<String, String> {
    let pairs: [(&str, &str); 3] = if physical {
        [("[L]", "µm"), ("[E]", "pN·µm"), ("[T]", "s")]
    } else {
        [
            ("[L]", "the unit of filament.length"),
            ("[E]", "the unit of filament.kt"),
            (
                "[T]",
                "the time unit that drag, length and bending_rigidity imply",
            ),
        ]
    };
    pairs
        .iter()
        .map(|(k, v)| ((*k).to_string(), (*v).to_string()))
        .collect()
}

/// The provenance record of the parameters `params` (and the physical filament they were
/// converted from, if any): the keys as given, the parameters with units, and the
/// dimensionless groups ℓp/L, EA·L/kT with the scales τ₁, F_c0, ε_c0.
pub fn parameter_record(
    params: &FilamentParams,
    physical: Option<&PhysicalFilament>,
) -> ParameterRecord {
    let u = units(physical.is_some());
    let q = |v: f64, unit: &str| Quantity::new(v, unit);
    let parameters = [
        ("length", q(params.length, u[0])),
        ("bending_rigidity", q(params.bending_rigidity, u[1])),
        ("stretch_rigidity", q(params.stretch_rigidity, u[2])),
        ("drag", q(params.drag, u[3])),
        ("kt", q(params.kt, u[4])),
    ];
    let groups = [
        ("persistence_ratio", q(params.persistence_ratio(), "1")),
        ("stretch_ratio", q(params.stretch_ratio(), "1")),
        ("tau1", q(params.tau1(), u[5])),
        ("euler_load", q(params.euler_load(), u[6])),
        ("euler_strain", q(params.euler_strain(), "1")),
    ];
    let map = |list: &[(&str, Quantity)]| {
        list.iter()
            .map(|(k, v)| ((*k).to_string(), v.clone()))
            .collect()
    };
    ParameterRecord {
        unit_system: if physical.is_some() {
            "physical"
        } else {
            "consistent"
        }
        .to_string(),
        given: physical.map_or_else(BTreeMap::new, |p| {
            p.given()
                .into_iter()
                .map(|(k, v, unit)| (k.to_string(), q(v, unit)))
                .collect()
        }),
        parameters: map(&parameters),
        groups: map(&groups),
    }
}

/// The report's note on a filament given in physical units: the keys as written, the
/// converted parameters and the dimensionless groups.
pub fn units_note(params: &FilamentParams, physical: &PhysicalFilament) -> String {
    let given: Vec<String> = physical
        .given()
        .iter()
        .map(|(k, v, _)| format!("{k} = {v}"))
        .collect();
    format!(
        "Filament in physical units ({}), converted to µm, s, pN: L = {:.4} µm, EI = {:.4e} pN·µm², \
         EA = {:.4e} pN, xi = {:.4e} pN·s/µm², kT = {:.4e} pN·µm; lp/L = {:.4}, EA·L/kT = {:.4e}, \
         tau1 = {:.4e} s, F_c0 = {:.4e} pN. Lengths in the tables are in µm, times in s.",
        given.join(", "),
        params.length,
        params.bending_rigidity,
        params.stretch_rigidity,
        params.drag,
        params.kt,
        params.persistence_ratio(),
        params.stretch_ratio(),
        params.tau1(),
        params.euler_load(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn actin() -> FilamentInput {
        FilamentInput {
            contour_length_um: Some(10.0),
            persistence_length_um: Some(17.0),
            viscosity_pa_s: Some(1.0e-3),
            diameter_nm: Some(7.0),
            temperature_k: Some(300.0),
            ..FilamentInput::default()
        }
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    /// Hand values: kT at 300 K = 1.380649e-23 J/K × 300 K = 4.141947e-21 J =
    /// 4.141947e-3 pN·µm (4.142 pN·nm); actin ℓp = 17 µm → EI = 17 × 4.141947e-3 =
    /// 7.041310e-2 pN·µm² (≈ 7 × 10⁻²⁶ N·m², the textbook value); ξ = 4π × 10⁻³ /
    /// (ln(10 µm / 0.007 µm) + ½) = 1.2566371e-2 / 7.7644 = 1.61846e-3 pN·s/µm²;
    /// τ₁ = ξL⁴/(π⁴EI) = 16.1846 / (97.40909 × 0.0704131) = 2.3597 s.
    #[test]
    fn actin_converts_to_hand_values() {
        let (p, physical) = actin().resolve().expect("valid");
        let physical = physical.expect("physical");
        assert!(close(p.kt, 4.141947e-3, 1e-6), "kT = {}", p.kt);
        assert!(close(p.kt * 1e3, 4.142, 1e-4), "kT = {} pN·nm", p.kt * 1e3);
        assert!(
            close(p.bending_rigidity, 7.041310e-2, 1e-6),
            "EI = {}",
            p.bending_rigidity
        );
        assert_eq!(p.length, 10.0);
        let ln = (10.0f64 / 0.007).ln();
        assert!(close(ln, 7.264430, 1e-6));
        assert!(close(p.drag, 1.618459e-3, 1e-5), "xi = {}", p.drag);
        assert!(close(p.persistence_ratio(), 1.7, 1e-12));
        assert!(close(p.tau1(), 2.3597, 1e-4), "tau1 = {}", p.tau1());
        assert!(close(p.stretch_ratio(), DEFAULT_STRETCH_RATIO, 1e-12));
        assert_eq!(
            physical.keys_of("bending_rigidity"),
            ["persistence_length_um", "temperature_k"]
        );
        assert_eq!(
            physical.keys_of("drag"),
            ["viscosity_pa_s", "diameter_nm", "contour_length_um"]
        );
        let record = parameter_record(&p, Some(&physical));
        assert_eq!(record.unit_system, "physical");
        assert_eq!(
            record.given["persistence_length_um"],
            Quantity::new(17.0, "µm")
        );
        assert_eq!(record.parameters["bending_rigidity"].unit, "pN·µm²");
        assert_eq!(record.groups["tau1"].unit, "s");
        assert!(units_note(&p, &physical).contains("lp/L = 1.700"));
    }

    /// EI and ξ given directly: taken as they are; EA given: kept.
    #[test]
    fn rigidity_and_drag_given_directly() {
        let input = FilamentInput {
            contour_length_um: Some(5.0),
            bending_rigidity_pn_um2: Some(0.07),
            drag_pn_s_per_um2: Some(2e-3),
            stretch_rigidity_pn: Some(4.4e4),
            temperature_k: Some(310.0),
            ..FilamentInput::default()
        };
        let (p, _) = input.resolve().expect("valid");
        assert_eq!(
            (p.bending_rigidity, p.drag, p.stretch_rigidity),
            (0.07, 2e-3, 4.4e4)
        );
        assert!(close(p.kt, 310.0 * 1.380649e-5, 1e-15));
    }

    #[test]
    fn consistent_tables_keep_their_defaults() {
        let input = FilamentInput {
            bending_rigidity: Some(2.0),
            ..FilamentInput::default()
        };
        let (p, physical) = input.resolve().expect("valid");
        assert!(physical.is_none());
        assert_eq!(
            p,
            FilamentParams {
                bending_rigidity: 2.0,
                ..FilamentParams::default()
            }
        );
        assert_eq!(
            parameter_record(&p, None).parameters["drag"].unit,
            "[E]*[T]/[L]^3"
        );
    }

    #[test]
    fn mixed_double_and_missing_keys_are_refused_by_name() {
        let err = |input: FilamentInput| input.resolve().expect_err("refused");
        let e = err(FilamentInput {
            length: Some(1.0),
            ..actin()
        });
        assert!(
            e.keys.contains(&"length") && e.keys.contains(&"contour_length_um"),
            "{e:?}"
        );
        assert!(e.message.contains("`length`") && e.message.contains("`persistence_length_um`"));
        let e = err(FilamentInput {
            bending_rigidity_pn_um2: Some(0.07),
            ..actin()
        });
        assert_eq!(e.keys, ["persistence_length_um", "bending_rigidity_pn_um2"]);
        let e = err(FilamentInput {
            drag_pn_s_per_um2: Some(1e-3),
            ..actin()
        });
        assert_eq!(e.keys, ["viscosity_pa_s", "drag_pn_s_per_um2"]);
        let e = err(FilamentInput {
            diameter_nm: None,
            ..actin()
        });
        assert_eq!(e.keys, ["diameter_nm", "viscosity_pa_s"]);
        let e = err(FilamentInput {
            temperature_k: None,
            ..actin()
        });
        assert_eq!(e.keys, ["temperature_k"]);
        let e = err(FilamentInput {
            persistence_length_um: None,
            ..actin()
        });
        assert!(
            e.message
                .contains("needs `persistence_length_um` or `bending_rigidity_pn_um2`")
        );
    }
}
