//! The finite-element filament with any ends (issue #29): the imposed DOFs, the rigid
//! modes, and the generalized eigenvalues against the continuum's tabulated wavenumbers
//! (O(h⁴) from above).

use langevin_fem::fem::{BeamModel, Mesh, generalized_modes};
use langevin_fem::params::{End, Ends, FilamentParams};

/// q₁L, q₂L of the continuum (standard tables, e.g. Blevins, *Formulas for natural
/// frequency and mode shape*, table 8-1; independent of this crate).
fn tabulated(ends: Ends) -> [f64; 2] {
    use End::*;
    match (ends.left, ends.right) {
        (Hinged, Hinged) => [std::f64::consts::PI, 2.0 * std::f64::consts::PI],
        (Clamped, Clamped) | (Free, Free) => [4.730_040_745, 7.853_204_624],
        (Clamped, Free) | (Free, Clamped) => [1.875_104_069, 4.694_091_133],
        (Clamped, Hinged) | (Hinged, Clamped) | (Hinged, Free) | (Free, Hinged) => {
            [3.926_602_312, 7.068_582_745]
        }
    }
}

fn beam(ends: Ends, n: usize) -> BeamModel {
    let p = FilamentParams {
        length: 2.0,
        bending_rigidity: 3.0,
        drag: 0.5,
        ..FilamentParams::default()
    };
    BeamModel::with_ends(p, Mesh::uniform(p.length, n).unwrap(), ends).unwrap()
}

/// Each end removes the DOFs it imposes; the hinged numbering is the one of
/// `BeamModel::new`.
#[test]
fn each_end_imposes_its_dofs() {
    for ends in Ends::all() {
        let b = beam(ends, 5);
        let fixed = |e: End| usize::from(e.fixes_deflection()) + usize::from(e.fixes_slope());
        assert_eq!(
            b.n_dofs(),
            12 - fixed(ends.left) - fixed(ends.right),
            "{ends}"
        );
        let first = b.node_deflection_index(0);
        assert_eq!(first.is_none(), ends.left.fixes_deflection(), "{ends}");
        assert_eq!(b.node_rotation_index(0).is_none(), ends.left.fixes_slope());
        assert_eq!(
            b.node_deflection_index(5).is_none(),
            ends.right.fixes_deflection()
        );
        assert_eq!(b.node_rotation_index(5).is_none(), ends.right.fixes_slope());
        // Free indices are the node order, without gaps.
        let mut seen: Vec<usize> = (0..6)
            .flat_map(|i| [b.node_deflection_index(i), b.node_rotation_index(i)])
            .flatten()
            .collect();
        let sorted = seen.clone();
        seen.sort_unstable();
        assert_eq!(seen, sorted);
        assert_eq!(seen, (0..b.n_dofs()).collect::<Vec<_>>());
    }
    let hinged = BeamModel::new(FilamentParams::default(), Mesh::uniform(1.0, 4).unwrap()).unwrap();
    let same = BeamModel::with_ends(
        FilamentParams::default(),
        Mesh::uniform(1.0, 4).unwrap(),
        Ends::HINGED,
    )
    .unwrap();
    assert_eq!(hinged.stiffness().to_dense(), same.stiffness().to_dense());
    assert_eq!(hinged.ends(), Ends::HINGED);
}

/// The rigid modes are exact null vectors of K, C-orthonormal, as many as the ends allow,
/// and C-orthogonal to every elastic mode; the elastic modes leave them out.
#[test]
fn rigid_modes_are_the_null_space_of_the_stiffness() {
    for ends in Ends::all() {
        let b = beam(ends, 6);
        let rigid = b.rigid_modes();
        assert_eq!(rigid.len(), ends.rigid_modes(), "{ends}");
        let k = b.stiffness().to_dense();
        let c = b.damping().to_dense();
        let kscale = k.amax();
        for (r, psi) in rigid.iter().enumerate() {
            let v = nalgebra::DVector::from_column_slice(psi);
            assert!((&k * &v).amax() <= 1e-12 * kscale, "{ends}: K psi_{r}");
            for (s, phi) in rigid.iter().enumerate() {
                let u = nalgebra::DVector::from_column_slice(phi);
                let want = if r == s { 1.0 } else { 0.0 };
                assert!((u.dot(&(&c * &v)) - want).abs() < 1e-12, "{ends}: {r},{s}");
            }
        }
        let gm = generalized_modes(&b).unwrap();
        assert_eq!(gm.len(), b.n_dofs() - rigid.len(), "{ends}");
        assert!(gm.rates[0] > 0.0);
        for psi in &rigid {
            let v = nalgebra::DVector::from_column_slice(psi);
            let proj = gm.vectors.transpose() * (&c * &v);
            assert!(proj.amax() < 1e-9, "{ends}: {:e}", proj.amax());
        }
    }
}

/// The first two rates converge to EI q⁴/ξ from above at O(h⁴): the error at 8
/// elements over the error at 16 is 2⁴ within ±15 %, for every pair of ends.
#[test]
fn rates_converge_to_the_continuum_at_fourth_order_from_above() {
    for ends in Ends::all() {
        let q = tabulated(ends);
        let errors: Vec<[f64; 2]> = [8, 16]
            .iter()
            .map(|&n| {
                let b = beam(ends, n);
                let p = b.params();
                let gm = generalized_modes(&b).unwrap();
                std::array::from_fn(|i| {
                    let qi = q[i] / p.length;
                    let exact = p.bending_rigidity * qi.powi(4) / p.drag;
                    (gm.rates[i] - exact) / exact
                })
            })
            .collect();
        for i in 0..2 {
            assert!(
                errors[0][i] > 0.0 && errors[1][i] > 0.0,
                "{ends}: {errors:?}"
            );
            let ratio = errors[0][i] / errors[1][i];
            assert!((13.6..=18.4).contains(&ratio), "{ends} mode {i}: {ratio}");
        }
    }
}
