//! Exact continuum theory of the filament with any ends (`langevin_fem::spectral::ends`,
//! issue #29), tested as an oracle before anything is judged by it.
//!
//! What: the wavenumbers of all nine pairs of ends against tabulated high-precision roots
//! and their asymptotes; the mode shapes up to n = 50 against high-precision values (and
//! the naive textbook formula shown to fail there); orthonormality, end conditions and the
//! beam equation; hinged–hinged identical to `HingedBeam`; the closed-form equilibrium
//! covariances against mode sums with rigorous tail bounds and against classical
//! compliances; the two-time correlation's limits and the honesty of its truncation bound;
//! the rigid modes' laws; and the `theory ... --ends` command line.
//!
//! Reference values: the constants below are printed by `docs/dev/ends_reference.py`
//! (mpmath 1.3.0, mp.dps = 50; independent of the Rust code: the textbook equations and
//! cos/sin/cosh/sinh eigenfunctions at 60 + 2β/ln 10 digits, normalized by quadrature).
//! Regenerate with `python3 docs/dev/ends_reference.py` and paste its output.
//!
//! Each comparison has a known-wrong answer that it must reject (the asymptote for the
//! roots, the naive formula for the shapes, a hinged mode for the orthogonality, a 10⁻⁸
//! error and the hinged formula for the closed forms), so that no test passes trivially.
//! Parameters: L = 2, EI = 3, ξ = 0.7, kT = 1.3 (`common::filament::sample`), so that a
//! wrong power of L, EI, ξ or kT cannot cancel. Nothing here is random.

// The reference constants are printed with more digits than an f64 holds (the parser
// rounds them correctly), and some of them are √2, 1/√2 or π to that precision.
#![allow(clippy::excessive_precision, clippy::approx_constant)]

mod common;

use common::filament::sample;
use common::{assert_no_panic, run, stderr_of, stdout_of};
use langevin_fem::params::{End, Ends};
use langevin_fem::spectral::{CharacteristicEquation, EndedBeam, HingedBeam, RigidMotion};
use serde_json::Value;
use std::f64::consts::PI;

// Printed by docs/dev/ends_reference.py (mpmath 1.3.0, mp.dps = 50); do not edit by hand.
// First five elastic roots beta_n = q_n L of each characteristic equation.
#[rustfmt::skip]
const ROOTS_SINE: [f64; 5] = [3.141592653589793238462643, 6.283185307179586476925287, 9.42477796076937971538793, 12.56637061435917295385057, 15.70796326794896619231322];
#[rustfmt::skip]
const ROOTS_COS_COSH_PLUS_ONE: [f64; 5] = [4.730040744862704026024048, 7.853204624095837556477067, 10.99560783800167090666903, 14.13716549125746417710592, 17.27875965739948143809107];
#[rustfmt::skip]
const ROOTS_COS_COSH_MINUS_ONE: [f64; 5] = [1.875104068711961166445308, 4.694091132974174576436392, 7.854757438237612564861009, 10.99554073487546699066735, 14.13716839104647058091705];
#[rustfmt::skip]
const ROOTS_TAN_TANH: [f64; 5] = [3.926602312047918778238533, 7.068582745628732088552959, 10.21017612281303054546821, 13.3517687777540931242097, 16.4933614313464097807736];

// (left, right, n, [(u = x/L, phi_n(u)); 9]): normalized int_0^1 phi^2 du = 1/2,
// first non-zero Taylor coefficient at u = 0 positive.
type ShapeRow = (&'static str, &'static str, usize, [(f64, f64); 9]);
#[rustfmt::skip]
const SHAPES: &[ShapeRow] = &[
    ("hinged", "hinged", 1, [(0.0, 0.0), (0.001, 3.1415874858795633519e-3), (0.02, 0.062790519529313376076), (0.25, 0.7071067811865475244), (0.5, 1.0), (0.73, 0.75011106963045954151), (0.98, 0.062790519529313376076), (0.999, 3.1415874858795633519e-3), (1.0, 0.0)]),
    ("hinged", "hinged", 7, [(0.0, 0.0), (0.001, 0.021989376092505109031), (0.02, 0.42577929156507264886), (0.25, -0.7071067811865475244), (0.5, -1.0), (0.73, -0.33873792024529138122), (0.98, 0.42577929156507264886), (0.999, 0.021989376092505109031), (1.0, 0.0)]),
    ("hinged", "hinged", 20, [(0.0, 0.0), (0.001, 0.062790519529313376076), (0.02, 0.95105651629515357212), (0.25, 0.0), (0.5, 0.0), (0.73, 0.95105651629515357212), (0.98, -0.95105651629515357212), (0.999, -0.062790519529313376076), (1.0, 0.0)]),
    ("hinged", "hinged", 50, [(0.0, 0.0), (0.001, 0.15643446504023086901), (0.02, 0.0), (0.25, 1.0), (0.5, 0.0), (0.73, 1.0), (0.98, 0.0), (0.999, -0.15643446504023086901), (1.0, 0.0)]),
    ("hinged", "clamped", 1, [(0.0, 0.0), (0.001, 4.0376150704063190747e-3), (0.02, 0.080674021305534043123), (0.25, 0.86372608868244154479), (0.5, 1.0216677933275308903), (0.73, 0.51605735555446267163), (0.98, 4.2466813358156437975e-3), (0.999, 1.0888037035432723793e-5), (1.0, 0.0)]),
    ("hinged", "clamped", 7, [(0.0, 0.0), (0.001, 0.02277457749144290629), (0.02, 0.43993916994146547774), (0.25, -0.55557020606185115786), (0.5, -0.92387152272885772733), (0.73, -0.79343525244785690464), (0.98, 0.12446691620527270553), (0.999, 3.6404153575036260437e-4), (1.0, 0.0)]),
    ("hinged", "clamped", 20, [(0.0, 0.0), (0.001, 0.063574348442082701435), (0.02, 0.95579301479833012664), (0.25, -0.19509032201612826785), (0.5, 0.38268343236507892811), (0.73, 0.63135277091600324579), (0.98, -0.66604263378454685666), (0.999, -2.8010846389103665157e-3), (1.0, 0.0)]),
    ("hinged", "clamped", 50, [(0.0, 0.0), (0.001, 0.15721014532087305015), (0.02, -0.015707317311820675753), (0.25, 0.98078528040323044913), (0.5, -0.38268343236508977173), (0.73, 0.84009355389894189252), (0.98, -0.72599341542738439339), (0.999, -0.016694795214856474609), (1.0, 0.0)]),
    ("hinged", "free", 1, [(0.0, 0.0), (0.001, 3.8186221531015623142e-3), (0.02, 0.076289670867001001178), (0.25, 0.79975160201174729228), (0.5, 0.82695825107942351813), (0.73, 0.027580690598819563134), (0.98, -1.3030683544208394072), (0.999, -1.4086561916881627963), (1.0, -1.4142135623730950488)]),
    ("hinged", "free", 7, [(0.0, 0.0), (0.001, 0.022774577483176022043), (0.02, 0.43993916977036480394), (0.25, -0.55557025997735329166), (0.5, -0.92388754229371578496), (0.73, -0.79645345432716317949), (0.98, -0.77230175260157153431), (0.999, -1.3820026768574581379), (1.0, -1.4142135623730950488)]),
    ("hinged", "free", 20, [(0.0, 0.0), (0.001, 0.063574348442082701435), (0.02, 0.95579301479833012664), (0.25, -0.19509032201612826785), (0.5, 0.38268343236510061535), (0.73, 0.63135281998275215305), (0.98, -0.26981699473659989781), (0.999, 1.3242461357641015428), (1.0, 1.4142135623730950488)]),
    ("hinged", "free", 50, [(0.0, 0.0), (0.001, 0.15721014532087305015), (0.02, -0.015707317311820675753), (0.25, 0.98078528040323044913), (0.5, -0.38268343236508977173), (0.73, 0.84009355389894189295), (0.98, -0.6658321777572442576), (0.999, 1.1909941364318969774), (1.0, 1.4142135623730950488)]),
    ("clamped", "hinged", 1, [(0.0, 0.0), (0.001, 1.0888037035432723793e-5), (0.02, 4.2466813358156437975e-3), (0.25, 0.45976890269367778406), (0.5, 1.0216677933275308903), (0.73, 0.90820582295790189749), (0.98, 0.080674021305534043123), (0.999, 4.0376150704063190747e-3), (1.0, 0.0)]),
    ("clamped", "hinged", 7, [(0.0, 0.0), (0.001, 3.6404153575036260437e-4), (0.02, 0.12446691620527270553), (0.25, -0.97840541245056545876), (0.5, -0.92387152272885772733), (0.73, -0.13312129601360927242), (0.98, 0.43993916994146547774), (0.999, 0.02277457749144290629), (1.0, 0.0)]),
    ("clamped", "hinged", 20, [(0.0, 0.0), (0.001, 2.8010846389103665157e-3), (0.02, 0.66604263378454685666), (0.25, 0.55557032058443262407), (0.5, -0.38268343236507892811), (0.73, 0.99479214176172646847), (0.98, -0.95579301479833012664), (0.999, -0.063574348442082701435), (1.0, 0.0)]),
    ("clamped", "hinged", 50, [(0.0, 0.0), (0.001, 0.016694795214856474609), (0.02, 0.72599341542738439339), (0.25, 0.8314696123025452422), (0.5, 0.38268343236508977173), (0.73, 0.97759993776479068683), (0.98, 0.015707317311820675753), (0.999, -0.15721014532087305015), (1.0, 0.0)]),
    ("clamped", "clamped", 1, [(0.0, 0.0), (0.001, 1.5795794757323552142e-5), (0.02, 6.1320653286813232952e-3), (0.25, 0.61032639157771614649), (0.5, 1.122988991421950122), (0.73, 0.67792535381484081438), (0.98, 6.1320653286813232952e-3), (0.999, 1.5795794757323552142e-5), (1.0, 0.0)]),
    ("clamped", "clamped", 7, [(0.0, 0.0), (0.001, 3.8947794381104392301e-4), (0.02, 0.132379164071491878), (0.25, -0.92192392061726299577), (0.5, -0.99998918302017408209), (0.73, -0.64822728516498916222), (0.98, 0.132379164071491878), (0.999, 3.8947794381104392301e-4), (1.0, 0.0)]),
    ("clamped", "clamped", 20, [(0.0, 0.0), (0.001, 2.8699063357889318908e-3), (0.02, 0.67677885845034840872), (0.25, 0.38268350431929635686), (0.5, 0.0), (0.73, 0.78043038749283712104), (0.98, -0.67677885845034840872), (0.999, -2.8699063357889318908e-3), (1.0, 0.0)]),
    ("clamped", "clamped", 50, [(0.0, 0.0), (0.001, 0.016856666939855424414), (0.02, 0.71415891120068727879), (0.25, 0.92387953251128676034), (0.5, 0.0), (0.73, 0.93544403082986732501), (0.98, -0.71415891120068727879), (0.999, -0.016856666939855424414), (1.0, 0.0)]),
    ("clamped", "free", 1, [(0.0, 0.0), (0.001, 2.4850574839412749965e-6), (0.02, 9.8535325972166479128e-4), (0.25, 0.13758290960024899635), (0.5, 0.48015819095327215546), (0.73, 0.89219564178731375722), (0.98, 1.3752802237827317759), (0.999, 1.4122668896487184583), (1.0, 1.4142135623730950488)]),
    ("clamped", "free", 7, [(0.0, 0.0), (0.001, 2.928499846406357632e-4), (0.02, 0.10189516384198609927), (0.25, -0.91959020154062355039), (0.5, 5.2034555221290780148e-5), (0.73, 1.0027279163694862144), (0.98, 0.83814427063136962607), (0.999, 1.3853348335536376554), (1.0, 1.4142135623730950488)]),
    ("clamped", "free", 20, [(0.0, 0.0), (0.001, 2.5995234583148026124e-3), (0.02, 0.63345142485515162547), (0.25, 0.92387969032701262596), (0.5, -1.0), (0.73, -0.047106497058976778586), (0.98, 0.21810715827499367225), (0.999, -1.3275781648409678552), (1.0, -1.4142135623730950488)]),
    ("clamped", "free", 50, [(0.0, 0.0), (0.001, 0.016213590769113180717), (0.02, 0.76050069232854287626), (0.25, 0.38268343236508978096), (0.5, 1.0), (0.73, -0.35347484377925712514), (0.98, 0.69743656251428017003), (0.999, -1.1943242458533453087), (1.0, -1.4142135623730950488)]),
    ("free", "hinged", 1, [(0.0, 1.4142135623730950488), (0.001, 1.4086561916881627963), (0.02, 1.3030683544208394072), (0.25, 0.068864817679426505649), (0.5, -0.82695825107942351813), (0.73, -0.83736196585947904225), (0.98, -0.076289670867001001178), (0.999, -3.8186221531015623142e-3), (1.0, 0.0)]),
    ("free", "hinged", 7, [(0.0, 1.4142135623730950488), (0.001, 1.3820026768574581379), (0.02, 0.77230175260157153431), (0.25, 0.98316514835589543952), (0.5, 0.92388754229371578496), (0.73, 0.13312138103949544393), (0.98, -0.43993916977036480394), (0.999, -0.022774577483176022043), (1.0, 0.0)]),
    ("free", "hinged", 20, [(0.0, 1.4142135623730950488), (0.001, 1.3242461357641015428), (0.02, -0.26981699473659989781), (0.25, -0.55557014545477182542), (0.5, 0.38268343236510061535), (0.73, -0.99479214176172646846), (0.98, 0.95579301479833012664), (0.999, 0.063574348442082701435), (1.0, 0.0)]),
    ("free", "hinged", 50, [(0.0, 1.4142135623730950488), (0.001, 1.1909941364318969774), (0.02, -0.6658321777572442576), (0.25, -0.83146961230254523196), (0.5, -0.38268343236508977173), (0.73, -0.97759993776479068683), (0.98, -0.015707317311820675753), (0.999, 0.15721014532087305015), (1.0, 0.0)]),
    ("free", "clamped", 1, [(0.0, 1.4142135623730950488), (0.001, 1.4122668896487184583), (0.02, 1.3752802237827317759), (0.25, 0.93019515835661148818), (0.5, 0.48015819095327215546), (0.73, 0.15882168820730749048), (0.98, 9.8535325972166479128e-4), (0.999, 2.4850574839412749965e-6), (1.0, 0.0)]),
    ("free", "clamped", 7, [(0.0, 1.4142135623730950488), (0.001, 1.3853348335536376554), (0.02, 0.83814427063136962607), (0.25, 0.92816886046238255237), (0.5, 5.2034555221290780148e-5), (0.73, -0.99702534590613743718), (0.98, 0.10189516384198609927), (0.999, 2.928499846406357632e-4), (1.0, 0.0)]),
    ("free", "clamped", 20, [(0.0, 1.4142135623730950488), (0.001, 1.3275781648409678552), (0.02, -0.21810715827499367225), (0.25, -0.92387937469556088629), (0.5, 1.0), (0.73, 0.047106404360308543224), (0.98, -0.63345142485515162547), (0.999, -2.5995234583148026124e-3), (1.0, 0.0)]),
    ("free", "clamped", 50, [(0.0, 1.4142135623730950488), (0.001, 1.1943242458533453087), (0.02, -0.69743656251428017003), (0.25, -0.3826834323650897625), (0.5, -1.0), (0.73, 0.35347484377925712431), (0.98, -0.76050069232854287626), (0.999, -0.016213590769113180717), (1.0, 0.0)]),
    ("free", "free", 1, [(0.0, 1.4142135623730950488), (0.001, 1.4076413223526730604), (0.02, 1.2827733930085339336), (0.25, -0.14028352122563012422), (0.5, -0.85959044035232920644), (0.73, -0.24266153999726069107), (0.98, 1.2827733930085339336), (0.999, 1.4076413223526730604), (1.0, 1.4142135623730950488)]),
    ("free", "free", 7, [(0.0, 1.4142135623730950488), (0.001, 1.3808919584164144857), (0.02, 0.75041315289205790105), (0.25, 0.92583514431959935285), (0.5, 1.000010816862820131), (0.73, 0.65066881146031604254), (0.98, 0.75041315289205790105), (0.999, 1.3808919584164144857), (1.0, 1.4142135623730950488)]),
    ("free", "free", 20, [(0.0, 1.4142135623730950488), (0.001, 1.3231354628051661587), (0.02, -0.28672848975308214126), (0.25, -0.3826833604108831866), (0.5, 0.0), (0.73, -0.78043042718382235066), (0.98, 0.28672848975308214126), (0.999, -1.3231354628051661587), (1.0, -1.4142135623730950488)]),
    ("free", "free", 50, [(0.0, 1.4142135623730950488), (0.001, 1.1898841204221557652), (0.02, -0.65493530065669006867), (0.25, -0.92387953251128675192), (0.5, 0.0), (0.73, -0.93544403082986732536), (0.98, 0.65493530065669006867), (0.999, -1.1898841204221557652), (1.0, -1.4142135623730950488)]),
];

// ---------------------------------------------------------------------------------------
// Fixtures
// ---------------------------------------------------------------------------------------

/// The filament of the tests (L = 2, EI = 3, ξ = 0.7, kT = 1.3: no power can cancel).
fn beam(ends: Ends) -> EndedBeam {
    EndedBeam::new(sample(), ends).expect("valid parameters")
}

/// kT L³/EI of [`sample`], the natural scale of every covariance.
fn kt_l3_ei() -> f64 {
    let p = sample();
    p.kt * p.length.powi(3) / p.bending_rigidity
}

/// The ends named `left-right`.
fn ends(name: &str) -> Ends {
    name.parse().expect("valid ends")
}

/// Every pair of ends but hinged–hinged.
fn non_hinged() -> impl Iterator<Item = Ends> {
    Ends::all().filter(|e| !e.is_hinged())
}

/// The tabulated roots of the equation of `e`.
fn tabulated_roots(e: Ends) -> [f64; 5] {
    match CharacteristicEquation::of(e) {
        CharacteristicEquation::SinZero => ROOTS_SINE,
        CharacteristicEquation::CosCoshPlusOne => ROOTS_COS_COSH_PLUS_ONE,
        CharacteristicEquation::CosCoshMinusOne => ROOTS_COS_COSH_MINUS_ONE,
        CharacteristicEquation::TanTanh => ROOTS_TAN_TANH,
    }
}

/// Composite Gauss–Legendre rule on [0, L]: `panels` panels of 16 nodes each (exact for
/// polynomials of degree 31 per panel). Nodes of P₁₆ by Newton's method from the
/// Tricomi guesses, weights 2/((1 − x²) P₁₆′(x)²).
fn quadrature(l: f64, panels: usize) -> Vec<(f64, f64)> {
    const M: usize = 16;
    let mut rule = Vec::new();
    for i in 0..M {
        let mut x = (PI * (i as f64 + 0.75) / (M as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=M {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = M as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / dp;
            x -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    let h = l / panels as f64;
    let mut out = Vec::with_capacity(panels * M);
    for p in 0..panels {
        let mid = (p as f64 + 0.5) * h;
        for &(x, w) in &rule {
            out.push((mid + 0.5 * h * x, 0.5 * h * w));
        }
    }
    out
}

/// ∫₀ᴸ f g dx by [`quadrature`].
fn inner(rule: &[(f64, f64)], f: impl Fn(f64) -> f64, g: impl Fn(f64) -> f64) -> f64 {
    rule.iter().map(|&(x, w)| w * f(x) * g(x)).sum()
}

/// The textbook clamped–free mode, cosh βu − cos βu − σ(sinh βu − sin βu) with
/// σ = (cosh β + cos β)/(sinh β + sin β), normalized to mean square ½ (its mean square
/// is 1) and signed like ours (φ″(0) = 2β² > 0): the naive formula the module docs warn
/// against.
fn naive_clamped_free(beta: f64, u: f64) -> f64 {
    let sigma = (beta.cosh() + beta.cos()) / (beta.sinh() + beta.sin());
    let x = beta * u;
    (x.cosh() - x.cos() - sigma * (x.sinh() - x.sin())) / 2f64.sqrt()
}

// ---------------------------------------------------------------------------------------
// 1. Wavenumbers
// ---------------------------------------------------------------------------------------

/// What: the first five wavenumbers qₙL of all nine pairs of ends against the tabulated
/// roots (mirror pairs share them), and the textbook values quoted in the physics notes.
/// Reference: `docs/dev/ends_reference.py` (mpmath, the textbook equations at 60 + 2β/ln10
/// digits). Tolerance: 1e-9 absolute as asked, and in fact 4e-15 relative (a few ulp:
/// the roots are computed to full precision).
/// Known-wrong: the asymptote (n + ν)π is rejected by the 1e-9 check at n = 1 for every
/// equation but sin β = 0.
#[test]
fn wavenumbers_match_tabulated_roots() {
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let table = tabulated_roots(e);
        for (i, &want) in table.iter().enumerate() {
            let got = b.wavenumber(i + 1) * l;
            assert!(
                (got - want).abs() <= 1e-9,
                "{e} n={}: {got} vs {want}",
                i + 1
            );
            assert!(
                (got / want - 1.0).abs() <= 4e-15,
                "{e} n={}: {got} vs {want}",
                i + 1
            );
        }
        let eq = CharacteristicEquation::of(e);
        assert_eq!(eq, CharacteristicEquation::of(e.mirrored()));
        if eq != CharacteristicEquation::SinZero {
            let asymptote = (1.0 + eq.asymptotic_offset()) * PI;
            assert!((asymptote - table[0]).abs() > 1e-9, "{e}: control");
        }
        assert!(b.wavenumber(0).is_nan());
    }
    let textbook = [
        ("free-free", 4.730040745),
        ("clamped-free", 1.875104069),
        ("clamped-hinged", 3.926602312),
        ("hinged-free", 3.926602312),
    ];
    for (name, want) in textbook {
        let got = beam(ends(name)).wavenumber(1) * sample().length;
        assert!((got - want).abs() < 1e-9, "{name}: {got}");
    }
}

/// What: qₙL → (n + ν)π (ν = ½ clamped–clamped and free–free, −½ clamped–free, ¼
/// clamped–hinged and hinged–free, 0 hinged–hinged), at the predicted exponential rate
/// δₙ = qₙL − (n + ν)π ≈ (−1)ⁿ⁺¹·2e^{−qₙL} (cos cosh = ±1) and ≈ −e^{−2qₙL} (tan = tanh);
/// and the rigorous lower bound qₙ ≥ (n + c)π/L of the tail bounds, for n ≤ 3000.
/// Reference: the expansions of sin δ = ±sech β and δ = −arctan e^{−2β} (module docs).
/// Tolerance: 2e-4 relative on δₙ where δₙ is far above rounding (it is the next term,
/// e^{−2β} relative); to 4 ulp of β at large n, where δₙ underflows.
#[test]
fn wavenumbers_approach_their_asymptotes() {
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let eq = CharacteristicEquation::of(e);
        let nu = eq.asymptotic_offset();
        let check: &[usize] = match eq {
            CharacteristicEquation::SinZero => &[],
            CharacteristicEquation::TanTanh => &[1, 2, 3],
            CharacteristicEquation::CosCoshMinusOne => &[3, 4, 5, 6],
            CharacteristicEquation::CosCoshPlusOne => &[2, 3, 4, 5, 6],
        };
        for &n in check {
            let beta = b.wavenumber(n) * l;
            let delta = beta - (n as f64 + nu) * PI;
            let predicted = match eq {
                CharacteristicEquation::TanTanh => -(-2.0 * beta).exp(),
                _ => {
                    let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
                    sign * 2.0 * (-beta).exp()
                }
            };
            assert!(
                (delta / predicted - 1.0).abs() < 2e-4,
                "{e} n={n}: δ = {delta:e}, predicted {predicted:e}"
            );
        }
        for n in [200usize, 1000, 100_000] {
            let beta = b.wavenumber(n) * l;
            let asym = (n as f64 + nu) * PI;
            assert!(
                (beta - asym).abs() <= 4.0 * f64::EPSILON * asym,
                "{e} n={n}"
            );
        }
        let mut last = 0.0;
        for n in 1..=3000 {
            let q = b.wavenumber(n);
            assert!(q > last, "{e}: not ascending at n={n}");
            assert!(
                q >= b.wavenumber_lower_bound(n),
                "{e}: lower bound fails at n={n}"
            );
            last = q;
        }
    }
}

// ---------------------------------------------------------------------------------------
// 2. Mode shapes
// ---------------------------------------------------------------------------------------

/// What: φₙ(x) for every pair of ends, n ∈ {1, 7, 20, 50}, at x/L ∈ {0, 0.001, 0.02,
/// 0.25, 0.5, 0.73, 0.98, 0.999, 1} (both ends and points inside their boundary layers),
/// against high-precision values.
/// Reference: `docs/dev/ends_reference.py` (mpmath: the textbook cos/sin/cosh/sinh form,
/// normalized by quadrature, at 60 + 2β/ln10 digits; printed to 20 digits).
/// Tolerance: 1e-13 absolute (φ is O(1); the phase βu carries the rounding of β, about
/// 3e-14 at n = 50; the worst error seen is 1.3e-14).
/// Known-wrong: see [`naive_shapes_lose_every_digit_at_n_50`].
#[test]
fn mode_shapes_match_high_precision_values_up_to_n_50() {
    let mut worst: f64 = 0.0;
    for &(left, right, n, points) in SHAPES {
        let b = beam(ends(&format!("{left}-{right}")));
        let l = b.params.length;
        for (u, want) in points {
            let got = b.mode_shape(n, u * l);
            let err = (got - want).abs();
            worst = worst.max(err);
            assert!(err <= 1e-13, "{left}-{right} n={n} u={u}: {got} vs {want}");
        }
    }
    assert!(worst > 0.0 || SHAPES.is_empty());
}

/// What: the comparison of [`mode_shapes_match_high_precision_values_up_to_n_50`] rejects
/// the textbook formula cosh − cos − σ(sinh − sin) of the clamped–free mode at n = 50,
/// while that same formula passes at n = 1: so the test can tell a stable evaluation
/// from a naive one.
/// Reference: the same table. Tolerance: the same comparison (1e-13; here 1e-12).
#[test]
fn naive_shapes_lose_every_digit_at_n_50() {
    let l = sample().length;
    for &(left, right, n, points) in SHAPES {
        if (left, right) != ("clamped", "free") || !(n == 1 || n == 50) {
            continue;
        }
        let beta = beam(ends("clamped-free")).wavenumber(n) * l;
        let worst = points
            .iter()
            .map(|&(u, want)| (naive_clamped_free(beta, u) - want).abs())
            .fold(0.0, f64::max);
        if n == 1 {
            assert!(worst < 1e-12, "naive n=1 should pass: {worst:e}");
        } else {
            assert!(
                worst.is_nan() || worst >= 1e-12,
                "naive n=50 should fail: {worst:e}"
            );
            assert!(
                worst.is_nan() || worst >= 1.0,
                "naive n=50 loses every digit: {worst:e}"
            );
        }
    }
}

/// What: ∫₀ᴸ φₙ φₘ dx = (L/2) δₙₘ for n, m ≤ 12 (and n = 50 with itself), and every
/// rigid mode ψ has ∫ψ² = L/2 and is orthogonal to the other rigid modes and to the
/// elastic modes. Reference: the normalization of the module docs.
/// Quadrature: 400 panels × 16 Gauss–Legendre nodes, exact to rounding for these smooth
/// functions (βh ≤ 0.8 per panel at n = 50). Tolerance: 1e-12·L.
/// Known-wrong: sin(πx/L), the hinged mode, is not orthogonal to the free–free
/// translation (∫ = √2 L/π): the check rejects it as a free–free mode.
#[test]
fn modes_are_orthonormal_and_orthogonal_to_rigid_modes() {
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let rule = quadrature(l, 400);
        let mut modes: Vec<usize> = (1..=12).collect();
        modes.push(50);
        for &n in &modes {
            for &m in &modes {
                let got = inner(&rule, |x| b.mode_shape(n, x), |x| b.mode_shape(m, x));
                let want = if n == m { l / 2.0 } else { 0.0 };
                assert!((got - want).abs() < 1e-12 * l, "{e} ({n}, {m}): {got}");
            }
        }
        let rigid = b.rigid_modes();
        assert_eq!(rigid.len(), e.rigid_modes(), "{e}");
        for (i, r) in rigid.iter().enumerate() {
            for (j, s) in rigid.iter().enumerate() {
                let got = inner(&rule, |x| r.shape(x), |x| s.shape(x));
                let want = if i == j { l / 2.0 } else { 0.0 };
                assert!(
                    (got - want).abs() < 1e-12 * l,
                    "{e} rigid ({i}, {j}): {got}"
                );
            }
            for &n in &modes {
                let got = inner(&rule, |x| r.shape(x), |x| b.mode_shape(n, x));
                assert!(got.abs() < 1e-12 * l, "{e} rigid {i} vs mode {n}: {got}");
            }
        }
    }
    let ff = beam(ends("free-free"));
    let l = ff.params.length;
    let rule = quadrature(l, 400);
    let translation = ff.rigid_modes()[0];
    let wrong = inner(&rule, |x| translation.shape(x), |x| (PI * x / l).sin());
    assert!(wrong.abs() >= 1e-12 * l, "control: {wrong}");
}

/// What: every φₙ satisfies its end conditions (hinged w = w″ = 0, clamped w = w′ = 0,
/// free w″ = w‴ = 0) and the ODE φ″″ = qₙ⁴φ; the sign convention (first non-zero Taylor
/// coefficient at x = 0 positive); and the analytic derivatives agree with finite
/// differences of `mode_shape`.
/// Reference: the definition of the modes. Tolerance: the end conditions and ODE through
/// the analytic derivatives to 1e-12 (relative to qᵏ, the size of the k-th derivative);
/// the finite differences with h = 10⁻³L (central, error (qh)²/6 relative, below 1e-3 for
/// n ≤ 5) and the fourth difference with h = 4·10⁻³L (error ≈ (qh)²/6 plus rounding
/// 16ε/(qh)⁴, below 3e-3 for n ≤ 5).
#[test]
fn modes_satisfy_end_conditions_and_the_beam_equation() {
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        for n in [1usize, 2, 3, 5, 20, 50] {
            let q = b.wavenumber(n);
            let d = |k: u32, x: f64| b.mode_shape_derivative(n, k, x) / q.powi(k as i32);
            for (end, x) in [(e.left, 0.0), (e.right, l)] {
                let orders: [u32; 2] = match end {
                    End::Hinged => [0, 2],
                    End::Clamped => [0, 1],
                    End::Free => [2, 3],
                };
                for k in orders {
                    assert!(
                        d(k, x).abs() < 1e-12,
                        "{e} n={n} x={x} order {k}: {}",
                        d(k, x)
                    );
                }
            }
            let lead = match e.left {
                End::Free => d(0, 0.0),
                End::Hinged => d(1, 0.0),
                End::Clamped => d(2, 0.0),
            };
            assert!(lead > 0.1, "{e} n={n}: leading Taylor coefficient {lead}");
            for i in 0..=20 {
                let x = l * i as f64 / 20.0;
                assert!((d(4, x) - d(0, x)).abs() < 1e-12, "{e} n={n} x={x}: ODE");
            }
            if n > 5 {
                continue;
            }
            for i in 1..20 {
                let x = l * i as f64 / 20.0;
                let f = |x: f64| b.mode_shape(n, x);
                let h = 1e-3 * l;
                let d1 = (f(x + h) - f(x - h)) / (2.0 * h);
                let d2 = (f(x + h) - 2.0 * f(x) + f(x - h)) / (h * h);
                assert!((d1 / q - d(1, x)).abs() < 1e-3, "{e} n={n} x={x}: φ′");
                assert!((d2 / (q * q) - d(2, x)).abs() < 1e-3, "{e} n={n} x={x}: φ″");
                let h = 4e-3 * l;
                let d4 = (f(x + 2.0 * h) - 4.0 * f(x + h) + 6.0 * f(x) - 4.0 * f(x - h)
                    + f(x - 2.0 * h))
                    / h.powi(4);
                assert!((d4 / q.powi(4) - f(x)).abs() < 3e-3, "{e} n={n} x={x}: φ″″");
            }
        }
    }
}

/// What: the bound K of `mode_shape_bound` holds for every mode sampled (n ≤ 300, and
/// n = 10⁴) on a fine grid, is not vacuous (below 2.5), and must exceed 1: at a free end
/// |φₙ| → √2 (the free end of a beam moves √2 times the interior amplitude).
/// Reference: the proof in the doc comment. Tolerance: none (a bound).
#[test]
fn mode_shape_bound_holds_and_is_needed() {
    for e in non_hinged() {
        let b = beam(e);
        let l = b.params.length;
        let k = b.mode_shape_bound();
        assert!(k < 2.5, "{e}: K = {k}");
        let mut modes: Vec<usize> = (1..=300).step_by(7).collect();
        modes.push(10_000);
        for n in modes {
            for i in 0..=4000 {
                let x = l * i as f64 / 4000.0;
                assert!(b.mode_shape(n, x).abs() <= k, "{e} n={n} x={x}");
            }
        }
        if e.right == End::Free {
            let tip = b.mode_shape(50, l).abs();
            assert!((tip - 2f64.sqrt()).abs() < 1e-12, "{e}: tip {tip}");
            assert!(k >= 2f64.sqrt(), "{e}: K = {k}");
        }
    }
    assert_eq!(beam(Ends::HINGED).mode_shape_bound(), 1.0);
}

// ---------------------------------------------------------------------------------------
// 3. Hinged–hinged is HingedBeam
// ---------------------------------------------------------------------------------------

/// What: both ends hinged, `EndedBeam` returns exactly what `HingedBeam` returns: rates,
/// variances, shapes, wavenumbers nπ/L, profile and covariance, correlation (value,
/// bound and mode count), spectra and τ₁.
/// Reference: `HingedBeam` (itself tested in `tests/spectral_reference.rs`).
/// Tolerance: bit-for-bit (1e-15 relative for the wavenumber nπ/L).
#[test]
fn hinged_hinged_equals_hinged_beam() {
    let p = sample();
    let e = beam(Ends::HINGED);
    let h = HingedBeam::new(p).unwrap();
    let l = p.length;
    for n in 1..=60 {
        assert_eq!(e.mode_rate(n), h.mode_rate(n));
        assert_eq!(e.mode_variance(n), h.mode_variance(n));
        let q = n as f64 * PI / l;
        assert!((e.wavenumber(n) / q - 1.0).abs() < 1e-15);
        assert_eq!(e.lorentzian(n, 0.3), h.lorentzian(n, 0.3));
        assert_eq!(
            e.sampled_spectrum(n, 0.01, 2.0),
            h.sampled_spectrum(n, 0.01, 2.0)
        );
        for i in 0..=16 {
            let x = l * i as f64 / 16.0;
            assert_eq!(e.mode_shape(n, x), h.mode_shape(n, x));
        }
    }
    assert_eq!(e.tau1(), p.tau1());
    for i in 0..=16 {
        let x = l * i as f64 / 16.0;
        assert_eq!(e.profile_variance(x), h.profile_variance(x));
        for j in 0..=16 {
            let y = l * j as f64 / 16.0;
            assert_eq!(
                e.equilibrium_covariance(x, y),
                h.equilibrium_covariance(x, y)
            );
        }
    }
    let tau = p.tau1();
    for (t, eta) in [(0.0, 0.3), (0.1, 0.1), (0.05, 0.4), (3.0, 3.5)] {
        let (t, eta) = (t * tau, eta * tau);
        assert_eq!(
            e.correlation(0.3, 1.7, t, eta, 1e-12).unwrap(),
            h.correlation(0.3, 1.7, t, eta, 1e-12).unwrap()
        );
        assert_eq!(
            e.correlation_truncated(0.3, 1.7, t, eta, 7).unwrap(),
            h.correlation_truncated(0.3, 1.7, t, eta, 7).unwrap()
        );
    }
    assert!(e.rigid_modes().is_empty());
}

// ---------------------------------------------------------------------------------------
// 4. Closed-form equilibrium covariance
// ---------------------------------------------------------------------------------------

/// What: the closed-form covariance kT·G(x, y) (and the profile at y = x) of every pair
/// of ends against its mode sum Σ_{n≤2000} σₙ² φₙ(x) φₙ(y), on an 11 × 11 grid including
/// both ends; and the profile formulas of the docs against `equilibrium_covariance(x, x)`.
/// Reference: equipartition, σₙ² = 2kT/(EI qₙ⁴ L), summed over the independently tested
/// modes. Tolerance: the series' own rigorous tail bound (about 2e-12·kTL³/EI) plus
/// 1e-14·kTL³/EI for rounding.
/// Known-wrong: the closed form × (1 + 10⁻⁸), and the hinged–hinged formula, are rejected
/// by the same comparison for every pair of ends.
#[test]
fn closed_form_covariance_matches_mode_sums() {
    let s = kt_l3_ei();
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let hinged = beam(Ends::HINGED);
        let (mut rejected_scaled, mut rejected_hinged) = (false, false);
        for i in 0..=10 {
            let x = l * i as f64 / 10.0;
            for j in 0..=10 {
                let y = l * j as f64 / 10.0;
                let series = b.covariance_series(x, y, 2000);
                assert!(series.truncation_error < 3e-12 * s, "{e}: bound {series:?}");
                let tol = series.truncation_error + 1e-14 * s;
                let closed = b.equilibrium_covariance(x, y);
                assert!(
                    (closed - series.value).abs() <= tol,
                    "{e} x={x} y={y}: closed {closed:e}, series {:e} ± {tol:e}",
                    series.value
                );
                assert_eq!(closed, b.equilibrium_covariance(y, x), "{e}: symmetry");
                let wrong = closed * (1.0 + 1e-8);
                rejected_scaled |= (wrong - series.value).abs() > tol;
                let wrong = hinged.equilibrium_covariance(x, y);
                rejected_hinged |= (wrong - series.value).abs() > tol;
            }
            let diag = b.profile_variance(x);
            let cov = b.equilibrium_covariance(x, x);
            assert!(
                (diag - cov).abs() <= 1e-15 * s,
                "{e} x={x}: {diag} vs {cov}"
            );
        }
        assert!(rejected_scaled, "{e}: a 1e-8 error went unnoticed");
        assert!(
            rejected_hinged || e.is_hinged(),
            "{e}: the hinged formula passed"
        );
    }
}

/// What: the classical compliances and end values quoted in the docs: clamped–free tip
/// kT L³/(3EI) and ⟨w²(x)⟩ = kT x³/(3EI); clamped–clamped midspan kT L³/(192EI); the
/// free–free ends kT L³/(105EI) and centre kT L³/(320EI); hinged–free's free end
/// 2kT L³/(105EI); clamped–hinged kT L³u³(1−u)²(4−u)/(12EI); mirrors by x → L − x.
/// Reference: beam tables (cantilever and fixed–fixed point-load deflections) and the
/// derivation in the module docs. Tolerance: 1e-14 relative (rounding).
#[test]
fn classical_compliances() {
    let p = sample();
    let (l, ei, kt) = (p.length, p.bending_rigidity, p.kt);
    let s = kt_l3_ei();
    let rel = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-14;
    let cf = beam(ends("clamped-free"));
    assert!(rel(cf.profile_variance(l), kt * l.powi(3) / (3.0 * ei)));
    for i in 1..=10 {
        let x = l * i as f64 / 10.0;
        assert!(rel(cf.profile_variance(x), kt * x.powi(3) / (3.0 * ei)));
        let fc = beam(ends("free-clamped"));
        assert!(rel(fc.profile_variance(l - x), kt * x.powi(3) / (3.0 * ei)));
        let u = x / l;
        let ch = beam(ends("clamped-hinged")).profile_variance(x);
        if u < 1.0 {
            assert!(rel(
                ch,
                s * u.powi(3) * (1.0 - u).powi(2) * (4.0 - u) / 12.0
            ));
        }
    }
    assert!(rel(
        beam(ends("clamped")).profile_variance(l / 2.0),
        s / 192.0
    ));
    let ff = beam(ends("free"));
    assert!(rel(ff.profile_variance(0.0), s / 105.0));
    assert!(rel(ff.profile_variance(l), s / 105.0));
    assert!(rel(ff.profile_variance(l / 2.0), s / 320.0));
    assert!(rel(
        beam(ends("hinged-free")).profile_variance(l),
        2.0 * s / 105.0
    ));
    assert!(rel(
        beam(ends("free-hinged")).profile_variance(0.0),
        2.0 * s / 105.0
    ));
    for e in Ends::all() {
        let b = beam(e);
        for (x, end) in [(0.0, e.left), (l, e.right)] {
            if end != End::Free {
                assert_eq!(b.profile_variance(x), 0.0, "{e} x={x}");
            }
        }
        let m = beam(e.mirrored());
        for i in 0..=10 {
            let x = l * i as f64 / 10.0;
            let (a, c) = (b.profile_variance(x), m.profile_variance(l - x));
            assert!((a - c).abs() <= 1e-15 * s, "{e} mirror at x={x}");
        }
    }
}

/// What: where there are rigid modes, the closed-form G is the projected (pseudo-inverse)
/// Green's function: ∫₀ᴸ G(x, y) ψ(x) dx = 0 for every rigid mode ψ and every y.
/// Reference: the definition (module docs). Quadrature: 200 panels × 16 nodes; G is a
/// polynomial of degree ≤ 5 in x on each side of y, and every y used is a panel edge, so
/// the rule is exact up to rounding. Tolerance: 1e-12·kTL⁴/EI.
#[test]
fn projected_green_function_is_orthogonal_to_rigid_modes() {
    let s = kt_l3_ei() * sample().length;
    for e in Ends::all().filter(|e| e.rigid_modes() > 0) {
        let b = beam(e);
        let l = b.params.length;
        let rule = quadrature(l, 200);
        for r in b.rigid_modes() {
            for j in 0..=8 {
                let y = l * j as f64 / 8.0;
                let got = inner(&rule, |x| b.equilibrium_covariance(x, y), |x| r.shape(x));
                assert!(got.abs() < 1e-12 * s, "{e} {} y={y}: {got:e}", r.name());
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// 5. The two-time correlation
// ---------------------------------------------------------------------------------------

/// What: ⟨w(x,t) w(y,η)⟩ at t = η = 40τ₁ equals the closed-form equilibrium covariance;
/// it is exactly 0 at t = 0; it decays with η − t.
/// Reference: the t = η → ∞ limit of the mode sum (module docs), whose remaining
/// transient Σ σₙ²φₙφₙ e^{−2λₙt} ≤ K²·(2kTL³/EI)·e^{−80}·Σβₙ⁻⁴ is far below rounding.
/// Tolerance: the reported bound plus 1e-14·kTL³/EI.
#[test]
fn correlation_tends_to_the_equilibrium_covariance() {
    let s = kt_l3_ei();
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let t = 40.0 * b.tau1();
        for (x, y) in [(0.0, 0.0), (0.3, 1.7), (l, l), (l, 0.9), (1.0, 1.0)] {
            let c = b.correlation(x, y, t, t, 1e-12).unwrap();
            let want = b.equilibrium_covariance(x, y);
            assert!(
                (c.value - want).abs() <= c.truncation_error + 1e-14 * s,
                "{e} ({x}, {y}): {c:?} vs {want:e}"
            );
            assert!(c.truncation_error <= 1e-12 * b.mode_variance(1));
            let zero = b.correlation(x, y, 0.0, t, 1e-12).unwrap();
            assert_eq!((zero.value, zero.truncation_error), (0.0, 0.0));
        }
        let near = b
            .correlation(l, l, t, t + 0.1 * b.tau1(), 1e-12)
            .unwrap()
            .value;
        let far = b
            .correlation(l, l, t, t + 2.0 * b.tau1(), 1e-12)
            .unwrap()
            .value;
        if b.profile_variance(l) > 0.0 {
            assert!(far < near && near < b.profile_variance(l), "{e}: no decay");
        }
    }
}

/// What: the truncation bound is honoured: for N ∈ {1, 2, 3, 5, 10, 30}, the truncated
/// sum differs from a converged one by at most the sum of both reported bounds; and the
/// bound is not vacuous (at N = 1, t = η = 0.05τ₁, within a factor 100 of the actual
/// error; it is 4 to 17 times the error there).
/// Reference: the converged correlation (tolerance 1e-14). Tolerance: the bounds plus
/// 1e-14·kTL³/EI for rounding.
#[test]
fn correlation_truncation_bound_is_honoured() {
    let s = kt_l3_ei();
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let tau = b.tau1();
        for (t, eta) in [(0.05, 0.05), (0.01, 0.02), (0.3, 0.3), (0.002, 0.002)] {
            let (t, eta) = (t * tau, eta * tau);
            for (x, y) in [(l, l), (0.0, 0.2), (0.77, 1.31)] {
                let long = b.correlation(x, y, t, eta, 1e-14).unwrap();
                for n in [1usize, 2, 3, 5, 10, 30] {
                    let short = b.correlation_truncated(x, y, t, eta, n).unwrap();
                    let err = (short.value - long.value).abs();
                    let tol = short.truncation_error + long.truncation_error + 1e-14 * s;
                    assert!(
                        err <= tol,
                        "{e} N={n} ({x},{y},{t},{eta}): {err:e} > {tol:e}"
                    );
                }
            }
        }
        let (t, x) = (0.05 * tau, 0.5 * l);
        let long = b.correlation(x, x, t, t, 1e-14).unwrap();
        let short = b.correlation_truncated(x, x, t, t, 1).unwrap();
        let err = (short.value - long.value).abs();
        assert!(
            short.truncation_error < 1e4 * err,
            "{e}: bound {short:?}, error {err:e}"
        );
    }
}

/// What: the rigid modes' diffusion laws: amplitude MSD 4kT t/(ξL); centre of mass
/// 2kT t/(ξL); angle 2kT t/(ξI_ζ) with I_ζ = L³/12 about the centre and L³/3 about an
/// end; the physical law is the amplitude law times the square of the shape's constant
/// (1/√2) or slope; and the rigid part of the correlation from rest,
/// Σψ(x)ψ(y)·4kT t/(ξL) (zero without rigid modes).
/// Reference: the derivations in `RigidMode::physical_msd`. Tolerance: 1e-14 relative.
#[test]
fn rigid_modes_diffuse_by_their_laws() {
    let p = sample();
    let (l, xi, kt) = (p.length, p.drag, p.kt);
    let rel = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-14;
    let t = 0.37;
    for e in Ends::all() {
        let b = beam(e);
        let rigid = b.rigid_modes();
        for r in &rigid {
            assert!(rel(r.amplitude_msd(t), 4.0 * kt * t / (xi * l)));
            let (want, factor) = match r.motion {
                RigidMotion::Translation => (2.0 * kt * t / (xi * l), r.shape(0.3).powi(2)),
                RigidMotion::Rotation { pivot } => {
                    let i = if pivot == l / 2.0 {
                        l.powi(3) / 12.0
                    } else {
                        l.powi(3) / 3.0
                    };
                    assert!(rel(r.moment_of_inertia().unwrap(), i));
                    let slope = (r.shape(l) - r.shape(0.0)) / l;
                    (2.0 * kt * t / (xi * i), slope * slope)
                }
            };
            assert!(rel(r.physical_msd(t), want), "{e} {}", r.name());
            assert!(rel(r.amplitude_msd(t) * factor, want), "{e} {}", r.name());
            assert!(r.amplitude_msd(-1.0).is_nan() && r.shape(l * 1.01).is_nan());
        }
        let names: Vec<String> = rigid.iter().map(|r| r.name()).collect();
        let expected: &[&str] = match (e.left, e.right) {
            (End::Free, End::Free) => &["translation", "rotation about the centre"],
            (End::Hinged, End::Free) => &["rotation about the hinge at x = 0"],
            (End::Free, End::Hinged) => &["rotation about the hinge at x = L"],
            _ => &[],
        };
        assert_eq!(names, expected, "{e}");
        let (x, y) = (0.4, 1.9);
        let got = b.rigid_correlation(x, y, t, 2.0 * t).unwrap();
        let want: f64 = rigid
            .iter()
            .map(|r| r.shape(x) * r.shape(y) * 4.0 * kt * t / (xi * l))
            .sum();
        assert!((got - want).abs() <= 1e-15 * want.abs().max(1e-300), "{e}");
    }
}

/// What: the per-mode spectra follow from the per-mode rate and variance: the Lorentzian
/// integrates to σₙ² (closed form 4σ²λ/(λ² + ω²) with ∫₀^∞ = σ²) and at f = 0 is 4σₙ²/λₙ;
/// the sampled spectrum tends to it as dt → 0. Reference: the OU spectra of
/// `HingedBeam`. Tolerance: 1e-12 relative; 1e-3 at dt = 10⁻⁴/λ (the aliasing
/// correction is (λdt)²/12 relative at f = 0).
#[test]
fn per_mode_spectra() {
    for e in non_hinged() {
        let b = beam(e);
        for n in [1usize, 4] {
            let (var, lam) = (b.mode_variance(n), b.mode_rate(n));
            assert!((b.lorentzian(n, 0.0) / (4.0 * var / lam) - 1.0).abs() < 1e-12);
            let dt = 1e-4 / lam;
            assert!((b.sampled_spectrum(n, dt, 0.0) / b.lorentzian(n, 0.0) - 1.0).abs() < 1e-3);
            let f = lam / (2.0 * PI);
            assert!((b.lorentzian(n, f) / (2.0 * var / lam) - 1.0).abs() < 1e-12);
            let mac = b.mode_autocovariance(n, 1.0 / lam);
            assert!((mac / (var / std::f64::consts::E) - 1.0).abs() < 1e-12);
        }
        assert!((b.tau1() * b.mode_rate(1) - 1.0).abs() < 1e-15);
    }
    // The cantilever relaxes (π/β₁)⁴ ≈ 7.9 times slower than the hinged filament.
    let ratio = beam(ends("clamped-free")).tau1() / sample().tau1();
    assert!((ratio - (PI / ROOTS_COS_COSH_MINUS_ONE[0]).powi(4)).abs() < 1e-12 * ratio);
}

/// What: bad input gives errors naming the parameter, its value and the allowed range,
/// never a panic; positions outside [0, L] give NaN from the plain functions.
/// Reference: the style guide's error rules.
#[test]
fn bad_input_is_rejected_with_named_errors() {
    let mut p = sample();
    p.bending_rigidity = -1.0;
    let err = EndedBeam::new(p, ends("clamped-free"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bending_rigidity") && err.contains("-1"),
        "{err}"
    );
    for e in Ends::all() {
        let b = beam(e);
        let l = b.params.length;
        let cases: [(f64, f64, f64, f64, f64, &str); 5] = [
            (-0.1, 0.5, 0.1, 0.2, 1e-9, "x must be in [0, 2]"),
            (0.5, 2.5, 0.1, 0.2, 1e-9, "y must be in [0, 2]"),
            (0.5, 0.5, 0.3, 0.2, 1e-9, "eta must be finite and >= t"),
            (0.5, 0.5, f64::NAN, 0.2, 1e-9, "t must be finite and >= 0"),
            (0.5, 0.5, 0.1, 0.2, 0.0, "tolerance must be finite and > 0"),
        ];
        for (x, y, t, eta, tol, needle) in cases {
            let err = b.correlation(x, y, t, eta, tol).unwrap_err().to_string();
            assert!(err.contains(needle), "{e}: {err}");
        }
        let err = b
            .correlation_truncated(0.5, 0.5, 0.1, 0.2, 200_000)
            .unwrap_err();
        assert!(err.to_string().contains("n_modes"), "{e}: {err}");
        for x in [-1e-9, l * 1.000001, f64::NAN, f64::INFINITY] {
            assert!(b.mode_shape(1, x).is_nan());
            assert!(b.profile_variance(x).is_nan());
            assert!(b.equilibrium_covariance(x, 0.5).is_nan());
            assert!(b.equilibrium_covariance(0.5, x).is_nan());
            assert!(b.covariance_series(x, 0.5, 3).value.is_nan());
        }
        assert!(b.mode_shape(0, 0.5).is_nan() && b.mode_rate(0).is_nan());
        assert!(b.mode_variance(0).is_nan() && b.mode_shape_derivative(0, 1, 0.5).is_nan());
    }
}

// ---------------------------------------------------------------------------------------
// 6. The command line
// ---------------------------------------------------------------------------------------

/// Runs `langevin-fem <args>` and returns (exit code, stdout, stderr), after checking it
/// did not panic.
fn cli(args: &[&str]) -> (Option<i32>, String, String) {
    let o = run(args);
    assert_no_panic(args, &o);
    (o.status.code(), stdout_of(&o), stderr_of(&o))
}

/// Runs a theory query that must succeed and parses its one JSON object.
fn cli_json(args: &[&str]) -> Value {
    let (code, out, err) = cli(args);
    assert_eq!(code, Some(0), "{args:?}: {err}");
    assert_eq!(out.lines().count(), 1, "{args:?}: {out}");
    serde_json::from_str(&out).expect("JSON")
}

/// What: `theory mode --n 3 --ends clamped-free` prints the wavenumber qₙ, qₙL, rate,
/// variance with its convention, the characteristic equation, and (none) rigid modes;
/// free–free and hinged–free list their rigid modes with the diffusion laws.
/// Reference: the library (tested above) and the tabulated root. Tolerance: 1e-15
/// relative (the same computation, printed in shortest round-trip form).
#[test]
fn cli_mode_with_ends() {
    let v = cli_json(&[
        "theory",
        "mode",
        "--n",
        "3",
        "--ends",
        "clamped-free",
        "--length",
        "2",
        "--bending-rigidity",
        "3",
        "--drag",
        "0.7",
        "--kt",
        "1.3",
    ]);
    let b = beam(ends("clamped-free"));
    assert_eq!(v["ends"], "clamped-free");
    assert_eq!(v["n"], 3);
    assert_eq!(v["characteristic_equation"], "cos qL cosh qL = -1");
    assert_eq!(v["wavenumber"].as_f64().unwrap(), b.wavenumber(3));
    let ql = v["wavenumber_length"].as_f64().unwrap();
    assert!((ql / ROOTS_COS_COSH_MINUS_ONE[2] - 1.0).abs() < 4e-15);
    assert_eq!(v["rate"].as_f64().unwrap(), b.mode_rate(3));
    assert_eq!(v["variance"].as_f64().unwrap(), b.mode_variance(3));
    let conv = v["convention"].as_str().unwrap();
    assert!(
        conv.contains("L/2") && conv.contains("2kT/(EI q_n⁴ L)"),
        "{conv}"
    );
    assert_eq!(v["rigid_modes"].as_array().unwrap().len(), 0);

    let v = cli_json(&["theory", "mode", "--n", "1", "--ends", "free-free"]);
    let rigid = v["rigid_modes"].as_array().unwrap();
    assert_eq!(rigid.len(), 2);
    assert_eq!(rigid[0]["name"], "translation");
    assert_eq!(rigid[0]["amplitude_msd_rate"].as_f64().unwrap(), 4.0);
    assert_eq!(rigid[0]["physical_msd_rate"].as_f64().unwrap(), 2.0);
    assert_eq!(rigid[1]["name"], "rotation about the centre");
    assert!((rigid[1]["physical_msd_rate"].as_f64().unwrap() - 24.0).abs() < 1e-13);
    assert!((rigid[1]["moment_of_inertia"].as_f64().unwrap() - 1.0 / 12.0).abs() < 1e-16);
    let ql = v["wavenumber_length"].as_f64().unwrap();
    assert!((ql - 4.730040745).abs() < 1e-9);

    let v = cli_json(&["theory", "mode", "--n", "2", "--ends", "hinged-free"]);
    let rigid = v["rigid_modes"].as_array().unwrap();
    assert_eq!(rigid.len(), 1);
    assert_eq!(rigid[0]["name"], "rotation about the hinge at x = 0");
    assert!((rigid[0]["physical_msd_rate"].as_f64().unwrap() - 6.0).abs() < 1e-14);
    assert_eq!(rigid[0]["shape"], "√(3/2) x/L");
}

/// What: the hinged output of `theory mode`, `variance` and `correlation` is
/// byte-identical to what it was before `--ends` existed, with or without `--ends hinged`
/// (`hinged-hinged` too).
/// Reference: the outputs recorded in `docs/src/reference/commands.md` before the change.
#[test]
fn cli_hinged_output_is_unchanged() {
    let cases: [(&[&str], &str); 3] = [
        (
            &["theory", "mode", "--n", "1"],
            r#"{"n":1,"rate":97.40909103400242,"variance":0.020531964509368675}"#,
        ),
        (
            &["theory", "variance", "--x", "0.5"],
            r#"{"variance":0.020833333333333332,"x":0.5}"#,
        ),
        (
            &[
                "theory",
                "correlation",
                "--x",
                "0.5",
                "--y",
                "0.5",
                "--t",
                "0.1",
                "--eta",
                "0.2",
            ],
            r#"{"correlation":1.2078345017516062e-6,"eta":0.2,"modes":1,"t":0.1,"truncation_error":4.17125092292952e-71,"x":0.5,"y":0.5}"#,
        ),
    ];
    for (args, want) in cases {
        for extra in [&[][..], &["--ends", "hinged"], &["--ends", "hinged-hinged"]] {
            let full: Vec<&str> = args.iter().chain(extra).copied().collect();
            let (code, out, err) = cli(&full);
            assert_eq!(code, Some(0), "{full:?}: {err}");
            assert_eq!(out, format!("{want}\n"), "{full:?}");
        }
    }
}

/// What: `theory variance` and `theory correlation` with `--ends`: the clamped–free tip
/// variance kT L³/(3EI), the ends and the rigid-mode count; the correlation's elastic part
/// equals the library's and its rigid part Σψψ·4kT t/(ξL).
/// Reference: the library. Tolerance: 1e-15 relative.
#[test]
fn cli_variance_and_correlation_with_ends() {
    let phys = [
        "--length",
        "2",
        "--bending-rigidity",
        "3",
        "--drag",
        "0.7",
        "--kt",
        "1.3",
    ];
    let mut args = vec!["theory", "variance", "--x", "2", "--ends", "clamped-free"];
    args.extend(phys);
    let v = cli_json(&args);
    assert_eq!(v["ends"], "clamped-free");
    assert_eq!(v["rigid_modes"], 0);
    let want = 1.3 * 8.0 / (3.0 * 3.0);
    assert!((v["variance"].as_f64().unwrap() / want - 1.0).abs() < 1e-15);

    let mut args = vec![
        "theory",
        "correlation",
        "--x",
        "0.4",
        "--y",
        "1.9",
        "--t",
        "0.2",
        "--eta",
        "0.3",
        "--ends",
        "free-free",
    ];
    args.extend(phys);
    let v = cli_json(&args);
    let b = beam(ends("free-free"));
    let c = b.correlation(0.4, 1.9, 0.2, 0.3, 1e-12).unwrap();
    assert_eq!(v["correlation"].as_f64().unwrap(), c.value);
    assert_eq!(v["modes"].as_u64().unwrap() as usize, c.n_modes);
    let rigid = b.rigid_correlation(0.4, 1.9, 0.2, 0.3).unwrap();
    assert_eq!(v["rigid_correlation"].as_f64().unwrap(), rigid);
    assert!(rigid != 0.0);
}

/// What: a bad `--ends` exits 2 with a message naming `--ends`, the value and the
/// allowed values, for each command; a bad value of another flag still names that flag.
/// Reference: the CLI's error rules (`src/error.rs`: exit 2 for bad input).
#[test]
fn cli_rejects_bad_ends() {
    for cmd in [
        &["theory", "mode", "--n", "2"][..],
        &["theory", "variance", "--x", "0.5"],
        &[
            "theory",
            "correlation",
            "--x",
            "0.5",
            "--y",
            "0.5",
            "--t",
            "0",
            "--eta",
            "1",
        ],
    ] {
        for bad in ["pinned", "clamped-", "free-fixed", "a-b-c", ""] {
            let full: Vec<&str> = cmd.iter().copied().chain(["--ends", bad]).collect();
            let (code, out, err) = cli(&full);
            assert_eq!(code, Some(2), "{full:?}: {err}");
            assert!(out.is_empty(), "{full:?}: {out}");
            for needle in ["--ends", &format!("{bad:?}"), "hinged, clamped, free"] {
                assert!(err.contains(needle), "{full:?}: {err} lacks {needle}");
            }
        }
    }
    let (code, _, err) = cli(&["theory", "mode", "--n", "0", "--ends", "free-free"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--n must be >= 1, got 0"), "{err}");
    let (code, _, err) = cli(&["theory", "variance", "--x", "3", "--ends", "free-free"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--x must be in [0, 1], got 3"), "{err}");
}
