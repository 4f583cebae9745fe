//! Every fixed seed of the integration tests, in one place and all distinct. A test draws
//! from `trajectory_rng(SEED, index)`, so its outcome is fixed by the seed; the scenes'
//! own seeds are in their TOML files.

// tests/compression_theory.rs
/// Monte Carlo check of ⟨F⟩ by importance weighting.
pub const SEED_COMPRESSION_MC: u64 = 0xC04D_5EED_0001;
/// KS test of the force distribution against rejection samples.
pub const SEED_COMPRESSION_KS: u64 = 0xC04D_5EED_0002;

// tests/spectral_reference.rs
pub const SEED_EQUILIBRIUM: u64 = 0x5EC7_1001;
pub const SEED_ENSEMBLE: u64 = 0x5EC7_1002;
pub const SEED_LARGE_STEP: u64 = 0x5EC7_1003;
pub const SEED_REPRODUCIBLE: u64 = 0x5EC7_1004;

// tests/membrane_reference.rs
/// Independent Gaussian mode amplitudes: point variance, covariance, ⟨ΔA⟩, Var ΔA.
pub const SEED_MEMBRANE_EQUILIBRIUM: u64 = 0x3E3B_7001;
/// Exact OU ensembles from rest: the two-time correlation (M4).
pub const SEED_MEMBRANE_FROM_REST: u64 = 0x3E3B_7002;
/// Exact OU ensembles from equilibrium: the stationary two-time covariance.
pub const SEED_MEMBRANE_STATIONARY: u64 = 0x3E3B_7003;
/// The amplitudes of the quadrature (Parseval) check of ΔA and the energy.
pub const SEED_MEMBRANE_QUADRATURE: u64 = 0x3E3B_7004;

// tests/stats_validation.rs
pub const SEED_IID_MEAN: u64 = 0x11D_0001;
pub const SEED_AR1_TAU: u64 = 0xA41_0002;
/// `stats_validation`: the pooled τ_int over several short AR(1) series.
pub const SEED_AR1_POOLED_TAU: u64 = 0x0900_17A0;
pub const SEED_AR1_MOMENTS: u64 = 0xA41_0003;
pub const SEED_BLOCKING: u64 = 0xB10C_0004;
pub const SEED_DECAY: u64 = 0xDECA_0005;
pub const SEED_NULL: u64 = 0x0_0006;
pub const SEED_POWER: u64 = 0x90E_0007;
pub const SEED_DECAY_POWER: u64 = 0x90E_0008;
pub const SEED_HOLM: u64 = 0x4013_0009;
pub const SEED_WELCH: u64 = 0x3E1C_000A;
/// The exact-null variance test of AR(1) series: p-value uniformity, tails, power.
pub const SEED_QUADFORM: u64 = 0x0AD_F00B;
/// The profile's null law (sums of correlated AR(1) modes): uniformity, power.
pub const SEED_WHITTLE: u64 = 0x0AD_F00C;
/// The two-time check's null law (sums of products of correlated normals).
pub const SEED_PRODUCTS: u64 = 0x0AD_F00D;
/// The jackknife correlation of a decay rate with the variance of the same series.
pub const SEED_DECAY_CORRELATION: u64 = 0xDECA_C00C;
/// Short AR(1) ensembles of the decay-rate lag rule (expected lag against pilot lag).
pub const SEED_DECAY_LAG: u64 = 0xDECA_01A6;
/// The χ² goodness of fit with bins growing with the sample: null and duplicated samples.
pub const SEED_GOF_BINS: u64 = 0x0B1D_500D;

// tests/fem_model.rs
/// Sample covariance of the noise generators.
pub const SEED_NOISE_COVARIANCE: u64 = 20_240_601;
/// Two generators seeded alike draw alike.
pub const SEED_NOISE_DETERMINISM: u64 = 1;

// tests/golden.rs
/// Seed of the golden traces (not the scenes' own seeds, so that editing a scene's seed
/// does not move its snapshot).
pub const GOLDEN_SEED: u64 = 0x0060_1DE2;

// tests/fuzz_scenes.rs
/// The scene fuzzer's generator (ChaCha): the same 1600 mutants on every run.
pub const SEED_SCENE_FUZZ: u64 = 0xF022_5CE4;

// tests/damaged_data.rs
/// The byte mutator of the damaged-data property test (ChaCha): the same mutants of the
/// valid .npy, CSV, data.json and shard.json on every run.
pub const SEED_DAMAGED_DATA: u64 = 0xDA3A_6ED0;

// tests/plate_model.rs
/// Random points and bicubic coefficients of the interpolation checks.
pub const SEED_PLATE_INTERPOLATION: u64 = 0xB1A7_E001;
/// Random free-DOF vectors of the element-noise and load-vector checks.
pub const SEED_PLATE_NOISE: u64 = 0xB1A7_E002;
