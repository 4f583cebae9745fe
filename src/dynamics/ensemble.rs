//! Parallel ensembles of independent trajectories with results independent of the thread
//! count.

/// Runs `f(j)` for `j` in `0..n` in parallel (rayon) and returns the results in index
/// order, or the first error in index order: the same result and the same error whatever
/// the thread count (every index runs; each stops at its own failure).
///
/// # Errors
/// The error of the smallest failing index.
pub fn par_indexed<T: Send>(
    n: u64,
    f: impl Fn(u64) -> crate::Result<T> + Sync + Send,
) -> crate::Result<Vec<T>> {
    use rayon::prelude::*;
    (0..n)
        .into_par_iter()
        .map(f)
        .collect::<Vec<_>>()
        .into_iter()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::par_indexed;
    use crate::error::Error;

    /// Results come back in index order, and of several failing indices the smallest one's
    /// error is returned, with 1 and with 4 worker threads.
    #[test]
    fn par_indexed_is_ordered_and_reports_the_first_error() {
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let ok = par_indexed(100, |j| Ok(j * j)).unwrap();
                assert_eq!(ok, (0..100).map(|j| j * j).collect::<Vec<u64>>());
                let err = par_indexed(100, |j| {
                    if j == 97 || j == 3 || j == 50 {
                        Err(Error::diverged(j, 1.0, format!("index {j}")))
                    } else {
                        Ok(j)
                    }
                })
                .unwrap_err();
                assert!(
                    err.to_string().contains("index 3"),
                    "{threads} threads: {err}"
                );
            });
        }
    }
}
