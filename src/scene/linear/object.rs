//! The object a linear run simulates, as the rest of the pipeline sees it: its continuum
//! reference ([`Continuum`]) and its finite-element model ([`FemObject`]). Everything else
//! — the integrators, the discrete references ([`DiscreteLaw`](crate::dynamics::DiscreteLaw)),
//! the observers, the checks — speaks of a [`LinearSystem`], its modes and positions on a
//! sampling line, whichever object it is.
//!
//! **Positions.** A linear run samples its object on a line: the filament's axis,
//! x ∈ [0, L]; the membrane's midline y = b/2, x ∈ [0, a]. Profile points and two-time
//! points are positions on that line (fractions of its length in the scene file).

use crate::error::Result;
use crate::fem::beam::{BeamModel, DeflectionProbe};
use crate::fem::chain::ChainModel;
use crate::fem::modal::{GeneralizedModes, generalized_modes};
use crate::fem::plate::PlateModel;
use crate::fem::plate_modes::PlateModes;
use crate::fem::system::LinearSystem;
use crate::spectral::EndedBeam;
use crate::spectral::membrane::{Membrane, MembraneMode};
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

/// Objects of fewer unknowns decompose faster than [`memoized`] keys them.
const MEMO_MIN_DOFS: usize = 100;
/// Decompositions [`memoized`] keeps (a 1000-element beam's: 32 MB each).
pub(crate) const MEMO_ENTRIES: usize = 2;

/// A dense decomposition of [`memoized`]: its key and its modes, computed once (`None`
/// if the decomposition failed).
type MemoEntry = (String, Arc<OnceLock<Option<GeneralizedModes>>>);

/// The last [`MEMO_ENTRIES`] dense decompositions ([`memoized`]).
static MODES_MEMO: Mutex<Vec<MemoEntry>> = Mutex::new(Vec::new());

/// `decompose()`, the dense generalized modes of `object` (O(n³)), computed once for
/// runs on one discretization: the runs of a scene or of a data set, the steps of a
/// convergence study over Δt. The modes do not depend on the integrator, the noise or
/// the step, and they are a pure function of the object, so the memo is keyed by the
/// object's whole state (its `Debug` text: every parameter, node, DOF number and
/// matrix entry, each float exactly): a hit is the same modes bit for bit. Two threads
/// asking for one key decompose it once. A failed decomposition is not kept (it is
/// repeated, to give its error).
fn memoized<T: std::fmt::Debug + std::ops::Deref<Target = LinearSystem>>(
    object: &T,
    decompose: impl Fn() -> Result<GeneralizedModes>,
) -> Result<GeneralizedModes> {
    if object.n_dofs() < MEMO_MIN_DOFS {
        return decompose();
    }
    let key = format!("{object:?}");
    let cell = {
        // A poisoned memo only lost an entry being written: its entries are whole.
        let mut memo = MODES_MEMO.lock().unwrap_or_else(PoisonError::into_inner);
        match memo.iter().find(|(k, _)| *k == key) {
            Some((_, cell)) => Arc::clone(cell),
            None => {
                let cell = Arc::new(OnceLock::new());
                if memo.len() == MEMO_ENTRIES {
                    memo.remove(0);
                }
                memo.push((key, Arc::clone(&cell)));
                cell
            }
        }
    };
    match cell.get_or_init(|| decompose().ok()) {
        Some(modes) => Ok(modes.clone()),
        None => decompose(),
    }
}

/// Relative tolerance of the membrane's continuum mode sums (their rigorous truncation
/// bound, relative to the variance of the slowest mode).
const MEMBRANE_TOLERANCE: f64 = 1e-12;

/// The continuum reference of a linear run's object.
#[derive(Debug, Clone)]
pub(crate) enum Continuum {
    /// The filament of eq. (2) with its ends (hinged: the sine modes of eq. 3; any
    /// ends, issue #29: [`EndedBeam`], the elastic modes, rigid motion projected out).
    Filament(EndedBeam),
    /// The Helfrich membrane of (M1) on its midline, with its checked modes (slowest
    /// first, [`Membrane::modes`]).
    Membrane {
        /// The membrane.
        membrane: Membrane,
        /// The checked modes.
        modes: Vec<MembraneMode>,
    },
}

impl Continuum {
    /// The membrane with its `count` slowest modes checked.
    ///
    /// # Errors
    /// As [`Membrane::modes`].
    pub(crate) fn membrane(membrane: Membrane, count: usize) -> Result<Self> {
        let modes = membrane.modes(count)?;
        Ok(Continuum::Membrane { membrane, modes })
    }

    /// The continuum of `scene`'s object: its filament, or its membrane with
    /// `sampling.modes` modes checked.
    ///
    /// # Errors
    /// Parameters the references refuse.
    pub(crate) fn of(scene: &crate::scene::Scene) -> Result<Self> {
        match scene.membrane {
            Some(m) => Continuum::membrane(Membrane::new(m)?, scene.sampling.modes),
            None => Ok(Continuum::Filament(EndedBeam::new(
                scene.filament,
                scene.ends,
            )?)),
        }
    }

    /// The continuum variance of checked mode `n` (1-based): eq. (3), or (M3).
    pub(crate) fn mode_variance(&self, n: usize) -> f64 {
        match self {
            Continuum::Filament(b) => b.mode_variance(n),
            Continuum::Membrane { membrane, modes } => membrane.mode_variance(modes[n - 1]),
        }
    }

    /// Length of the sampling line: L, or the membrane's width a.
    pub(crate) fn line_length(&self) -> f64 {
        match self {
            Continuum::Filament(b) => b.params.length,
            Continuum::Membrane { membrane, .. } => membrane.params.width,
        }
    }

    /// The continuum rate of checked mode `n` (1-based): π⁴n⁴EI/(ξL⁴), or c_q/ξ.
    pub(crate) fn mode_rate(&self, n: usize) -> f64 {
        match self {
            Continuum::Filament(b) => b.mode_rate(n),
            Continuum::Membrane { membrane, modes } => membrane.mode_rate(modes[n - 1]),
        }
    }

    /// The membrane's checked mode `n` (1-based); `None` for the filament.
    pub(crate) fn mode_label(&self, n: usize) -> Option<MembraneMode> {
        match self {
            Continuum::Filament(_) => None,
            Continuum::Membrane { modes, .. } => modes.get(n - 1).copied(),
        }
    }

    /// The continuum ⟨w²(x)⟩ at position `x` of the sampling line.
    ///
    /// # Errors
    /// The membrane's mode-sum errors (a position outside the rectangle).
    pub(crate) fn profile_variance(&self, x: f64) -> Result<f64> {
        match self {
            Continuum::Filament(b) => Ok(b.profile_variance(x)),
            Continuum::Membrane { membrane, .. } => Ok(membrane
                .point_variance(x, midline(membrane), MEMBRANE_TOLERANCE)?
                .value),
        }
    }

    /// The continuum ⟨w(x, t) w(y, η)⟩ from rest (eq. 4, or (M4) on the midline).
    ///
    /// # Errors
    /// Invalid positions or times.
    pub(crate) fn correlation(&self, x: f64, y: f64, t: f64, eta: f64) -> Result<f64> {
        match self {
            Continuum::Filament(b) => Ok(b.correlation(x, y, t, eta, 1e-12)?.value),
            Continuum::Membrane { membrane, .. } => {
                let m = midline(membrane);
                Ok(membrane
                    .correlation((x, m), (y, m), t, eta, MEMBRANE_TOLERANCE)?
                    .value)
            }
        }
    }
}

/// The membrane's sampling line y = b/2.
fn midline(membrane: &Membrane) -> f64 {
    0.5 * membrane.params.height
}

/// The finite-element model of a linear run's object.
#[derive(Debug, Clone)]
pub(crate) enum FemObject {
    /// Hermite-cubic beam elements.
    Beam(Box<BeamModel>),
    /// The hinged filament as a chain of nodes: another program's finite-difference or
    /// bead-spring discretization (issue #31).
    Chain(Box<ChainModel>),
    /// Bogner–Fox–Schmit plate elements on a uniform mesh, with their separable modes
    /// and the continuum modes that are checked (their acoustic modes come first in
    /// [`FemObject::modes`]).
    Plate {
        /// The plate.
        plate: Box<PlateModel>,
        /// Its separable modes.
        modes: Box<PlateModes>,
        /// The checked continuum modes, slowest first.
        checked: Vec<MembraneMode>,
        /// Periodic: `b/(ab)` (`b = ∫N`, the assembled loads), so that the spatial mean
        /// height of a state `x` is `meanᵀx`; `None` simply supported.
        mean: Option<Vec<f64>>,
    },
}

impl FemObject {
    /// The linear system the model assembles.
    pub(crate) fn system(&self) -> &LinearSystem {
        match self {
            FemObject::Beam(b) => b,
            FemObject::Chain(c) => c,
            FemObject::Plate { plate, .. } => plate,
        }
    }

    /// The plate of a membrane with `nx × ny` elements, its separable modes, and `checked`
    /// (continuum modes, each resolved by the mesh).
    ///
    /// # Errors
    /// As [`PlateModel::new`] and [`PlateModes::new`]; [`crate::Error::InvalidParameter`]
    /// naming `sampling.modes` if a checked mode is not resolved by the mesh.
    pub(crate) fn plate(
        membrane: &Membrane,
        nx: usize,
        ny: usize,
        checked: Vec<MembraneMode>,
    ) -> Result<Self> {
        let plate = PlateModel::new(membrane.params, nx, ny)?;
        let modes = PlateModes::new(&plate)?;
        if let Some(m) = checked.iter().find(|m| modes.acoustic(**m).is_none()) {
            return Err(crate::Error::invalid(
                "sampling.modes",
                checked.len(),
                format!(
                    "at most the modes a {nx} x {ny} mesh resolves (mode ({}, {}) is not)",
                    m.m, m.n
                ),
            ));
        }
        let area = membrane.params.area();
        let mean = plate.zero_mode().map(|_| {
            let mut b = plate.assembled_load_vector();
            b.iter_mut().for_each(|v| *v /= area);
            b
        });
        Ok(FemObject::Plate {
            plate: Box::new(plate),
            modes: Box::new(modes),
            checked,
            mean,
        })
    }

    /// The largest rate λ_max of `(K, C)` by an O(n) inertia bisection
    /// ([`BeamModel::max_rate`]).
    ///
    /// # Errors
    /// As [`BeamModel::max_rate`].
    pub(crate) fn max_rate(&self) -> Result<f64> {
        match self {
            FemObject::Beam(b) => b.max_rate(),
            FemObject::Chain(c) => Ok(c.max_rate()),
            FemObject::Plate { plate, .. } => plate.max_rate(),
        }
    }

    /// The generalized modes of `(K, C)`, signed by the object's rule; the first ones are
    /// those of the continuum's checked modes, in their order.
    ///
    /// # Errors
    /// As [`generalized_modes`].
    pub(crate) fn modes(&self) -> Result<GeneralizedModes> {
        match self {
            FemObject::Beam(b) => memoized(b.as_ref(), || generalized_modes(b)),
            FemObject::Chain(c) => memoized(c.as_ref(), || c.modes()),
            FemObject::Plate { modes, checked, .. } => {
                let all = modes.generalized_modes()?;
                // The checked modes' acoustic columns first, in the continuum's order,
                // then every other column in rate order (the periodic zero mode is not
                // among them: PlateModes::generalized_modes leaves it out).
                let mut order: Vec<usize> = Vec::with_capacity(all.len());
                for m in checked {
                    let j = modes
                        .dense_column(*m)
                        .ok_or_else(|| crate::Error::Numerical {
                            routine: "FemObject::modes".into(),
                            detail: format!("mode ({}, {}) is not resolved", m.m, m.n),
                        })?;
                    order.push(j);
                }
                let rest: Vec<usize> = (0..all.len()).filter(|j| !order.contains(j)).collect();
                order.extend(rest);
                Ok(GeneralizedModes {
                    rates: DVector::from_iterator(order.len(), order.iter().map(|&j| all.rates[j])),
                    vectors: DMatrix::from_fn(all.vectors.nrows(), order.len(), |r, c| {
                        all.vectors[(r, order[c])]
                    }),
                })
            }
        }
    }

    /// The field at position `x` of the sampling line for state `state` (NaN outside).
    pub(crate) fn value_at(&self, state: &[f64], x: f64) -> f64 {
        match self {
            // The rigid motion of free ends is projected out, as the continuum's.
            FemObject::Beam(b) => b.elastic_deflection_at(state, x),
            FemObject::Chain(c) => c.value_at(state, x),
            FemObject::Plate { plate, mean, .. } => {
                let h = plate.height_at(state, x, 0.5 * plate.params().height);
                // Periodic: the height relative to the spatial mean (the q = 0 mode, a
                // free translation, is excluded as in the continuum).
                match mean {
                    Some(m) => h - m.iter().zip(state).map(|(a, b)| a * b).sum::<f64>(),
                    None => h,
                }
            }
        }
    }

    /// The points `xs` of the sampling line prepared for [`Self::values_with`]: a beam's
    /// deflection functionals ([`BeamModel::deflection_probe`]), the points themselves
    /// otherwise.
    pub(crate) fn probes(&self, xs: &[f64]) -> Probes {
        Probes {
            xs: xs.to_vec(),
            beam: self
                .beam()
                .map(|b| xs.iter().map(|&x| b.deflection_probe(x)).collect()),
            rigid: RefCell::new(Vec::new()),
        }
    }

    /// [`Self::value_at`] of `state` at every point of `probes` into `out`, bit for bit:
    /// for a beam with the functionals prepared once and the rigid amplitudes formed
    /// once per state instead of once per point.
    pub(crate) fn values_with(&self, probes: &Probes, state: &[f64], out: &mut [f64]) {
        match (self.beam(), &probes.beam) {
            (Some(b), Some(points)) => {
                let mut rigid = probes.rigid.borrow_mut();
                rigid.resize(b.ends().rigid_modes(), 0.0);
                b.rigid_amplitudes(state, &mut rigid);
                for (o, p) in out.iter_mut().zip(points) {
                    *o = p.elastic(state, &rigid);
                }
            }
            _ => {
                for (o, &x) in out.iter_mut().zip(&probes.xs) {
                    *o = self.value_at(state, x);
                }
            }
        }
    }

    /// The positions of the mesh nodes on the sampling line (where the trajectory files
    /// record the field).
    pub(crate) fn line_nodes(&self) -> Vec<f64> {
        match self {
            FemObject::Beam(b) => b.mesh().nodes().to_vec(),
            FemObject::Chain(c) => c.nodes(),
            FemObject::Plate { plate, .. } => {
                let (nx, _) = plate.elements();
                let a = plate.params().width;
                (0..=nx).map(|i| a * i as f64 / nx as f64).collect()
            }
        }
    }

    /// The beam, if the object is one (its nodal slopes feed the small-slope warning).
    pub(crate) fn beam(&self) -> Option<&BeamModel> {
        match self {
            FemObject::Beam(b) => Some(b),
            FemObject::Chain(_) | FemObject::Plate { .. } => None,
        }
    }
}

/// Points of the sampling line prepared for repeated evaluation
/// ([`FemObject::probes`]).
#[derive(Debug)]
pub(crate) struct Probes {
    /// The points.
    pub(crate) xs: Vec<f64>,
    /// A beam's deflection functionals at them.
    beam: Option<Vec<DeflectionProbe>>,
    /// Scratch space of the rigid amplitudes.
    rigid: RefCell<Vec<f64>>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::membrane::{MembraneBoundary, MembraneParams};

    /// The memoized dense modes are those of a fresh decomposition, bit for bit, for
    /// every object asked in turn (beams that differ only in rigidity, only in drag,
    /// only in their ends; a chain), whether the object is new to the memo or was just
    /// asked: a key missing any of the object's state would hand one object another's
    /// modes.
    #[test]
    fn memoized_modes_are_the_objects_own() {
        use crate::params::{Ends, FilamentParams};
        let p = FilamentParams::default();
        let beam = |p: FilamentParams, ends: Ends| {
            let mesh = crate::fem::mesh::Mesh::uniform(p.length, 60).unwrap();
            FemObject::Beam(Box::new(BeamModel::with_ends(p, mesh, ends).unwrap()))
        };
        let stiffer = FilamentParams {
            bending_rigidity: 2.0 * p.bending_rigidity,
            ..p
        };
        let draggier = FilamentParams {
            drag: 3.0 * p.drag,
            ..p
        };
        let objects = [
            beam(p, Ends::default()),
            beam(stiffer, Ends::default()),
            beam(draggier, Ends::default()),
            beam(p, "clamped-clamped".parse().unwrap()),
            FemObject::Chain(Box::new(ChainModel::new(p, 150).unwrap())),
        ];
        for obj in objects.iter().chain(objects.iter().rev()) {
            assert!(obj.system().n_dofs() >= MEMO_MIN_DOFS);
            let fresh = match obj {
                FemObject::Beam(b) => generalized_modes(b).unwrap(),
                FemObject::Chain(c) => c.modes().unwrap(),
                FemObject::Plate { .. } => unreachable!(),
            };
            for _ in 0..2 {
                let got = obj.modes().unwrap();
                assert_eq!(got.rates, fresh.rates);
                assert_eq!(got.vectors, fresh.vectors);
            }
        }
    }

    /// The membrane's continuum on its midline is the membrane's own (M3)–(M4) at y = b/2,
    /// its checked modes slowest first.
    #[test]
    fn membrane_continuum_is_the_midline_of_the_membrane() {
        let mb = Membrane::new(MembraneParams {
            tension: 3.0,
            height: 0.6,
            boundary: MembraneBoundary::SimplySupported,
            ..MembraneParams::default()
        })
        .unwrap();
        let c = Continuum::membrane(mb, 4).unwrap();
        assert_eq!(c.line_length(), 1.0);
        let rates: Vec<f64> = (1..=4).map(|n| c.mode_rate(n)).collect();
        assert!(rates.windows(2).all(|w| w[0] <= w[1]), "{rates:?}");
        let want = mb.point_variance(0.3, 0.3, 1e-12).unwrap().value;
        assert_eq!(c.profile_variance(0.3).unwrap(), want);
        let want = mb
            .correlation((0.3, 0.3), (0.5, 0.3), 0.01, 0.02, 1e-12)
            .unwrap()
            .value;
        assert_eq!(c.correlation(0.3, 0.5, 0.01, 0.02).unwrap(), want);
        assert!(c.profile_variance(1.5).is_err());
    }

    /// The plate's modes put the checked continuum modes first, by label: on a square the
    /// equal-rate (1, 2) and (2, 1) get their own columns — (1, 2) vanishes on the midline
    /// y = b/2, (2, 1) does not — every column satisfies Kφ = λCφ, and the first rates are
    /// the acoustic ones. Periodic: the field is measured from the spatial mean, so the
    /// zero mode (a uniform translation) reads 0 everywhere.
    #[test]
    fn plate_modes_follow_the_checked_modes_by_label() {
        let mb = Membrane::new(MembraneParams::default()).unwrap();
        let checked = mb.modes(4).unwrap();
        let obj = FemObject::plate(&mb, 6, 6, checked.clone()).unwrap();
        let gm = obj.modes().unwrap();
        let FemObject::Plate { modes, .. } = &obj else {
            unreachable!()
        };
        let sys = obj.system();
        for (i, m) in checked.iter().enumerate() {
            assert_eq!(gm.rates[i], modes.acoustic(*m).unwrap().rate);
            let col: Vec<f64> = gm.vectors.column(i).iter().copied().collect();
            let (mut kx, mut cx) = (vec![0.0; col.len()], vec![0.0; col.len()]);
            sys.stiffness().mul_vec(&col, &mut kx);
            sys.damping().mul_vec(&col, &mut cx);
            let res = kx
                .iter()
                .zip(&cx)
                .map(|(k, c)| (k - gm.rates[i] * c).abs())
                .fold(0.0, f64::max);
            let scale = kx.iter().map(|v| v.abs()).fold(0.0, f64::max);
            assert!(res <= 1e-9 * scale, "mode {m:?}: residual {res:e}");
            let on_midline = obj.value_at(&col, 0.3);
            let peak = (0..=20)
                .map(|k| obj.value_at(&col, k as f64 / 20.0).abs())
                .fold(0.0, f64::max);
            if m.n % 2 == 0 {
                assert!(
                    on_midline.abs() < 1e-9,
                    "{m:?} on the midline: {on_midline}"
                );
            } else {
                assert!(peak > 0.1, "{m:?} peak {peak}");
            }
        }
        assert_eq!(gm.len(), sys.n_dofs());
        let per = Membrane::new(MembraneParams {
            boundary: MembraneBoundary::Periodic,
            ..MembraneParams::default()
        })
        .unwrap();
        let obj = FemObject::plate(&per, 4, 4, per.modes(3).unwrap()).unwrap();
        let FemObject::Plate { plate, .. } = &obj else {
            unreachable!()
        };
        let zero = plate.zero_mode().unwrap();
        assert!(obj.value_at(&zero, 0.37).abs() < 1e-12);
        assert_eq!(obj.modes().unwrap().len(), plate.n_dofs() - 1);
        let too_many = per.modes(200).unwrap();
        assert!(FemObject::plate(&per, 4, 4, too_many).is_err());
    }
}
