//! One-dimensional meshes of the filament axis `[0, L]`.

use crate::error::{Error, Result, require_positive};

/// A 1D mesh of the filament axis: node coordinates `0 = x_0 < x_1 < … < x_N = L`,
/// element `e` being `[x_e, x_{e+1}]` with length `h_e = x_{e+1} − x_e`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    nodes: Vec<f64>,
}

impl Mesh {
    /// Uniform mesh of `n_elements` elements of length `h = L/N`: `x_i = i·L/N`
    /// (the last node is exactly `L`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `length` is not finite and positive or
    /// `n_elements == 0`.
    pub fn uniform(length: f64, n_elements: usize) -> Result<Mesh> {
        require_positive("length", length)?;
        if n_elements == 0 {
            return Err(Error::invalid("n_elements", n_elements, ">= 1"));
        }
        let n = n_elements as f64;
        let nodes = (0..=n_elements)
            .map(|i| {
                if i == n_elements {
                    length
                } else {
                    length * (i as f64) / n
                }
            })
            .collect();
        Mesh::from_nodes(nodes)
    }

    /// Mesh from explicit node coordinates.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless there are at least 2 nodes, all finite, the
    /// first equal to 0 and the sequence strictly increasing.
    pub fn from_nodes(nodes: Vec<f64>) -> Result<Mesh> {
        if nodes.len() < 2 {
            return Err(Error::invalid(
                "mesh nodes",
                format!("{} node(s)", nodes.len()),
                "at least 2 nodes",
            ));
        }
        if let Some((i, x)) = nodes.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(Error::invalid(format!("mesh node {i}"), x, "finite"));
        }
        if nodes[0] != 0.0 {
            return Err(Error::invalid("mesh node 0", nodes[0], "= 0"));
        }
        for i in 1..nodes.len() {
            if nodes[i] <= nodes[i - 1] {
                return Err(Error::invalid(
                    format!("mesh node {i}"),
                    nodes[i],
                    format!("> previous node {}", nodes[i - 1]),
                ));
            }
        }
        Ok(Mesh { nodes })
    }

    /// Geometrically graded mesh: element lengths `h_e = h_0·r^e` with
    /// `r = ratio^{1/(N−1)}`, so that `h_{N−1}/h_0 = ratio`, and `Σ h_e = L`
    /// (`h_0 = L(r−1)/(r^N−1)`; uniform when `ratio = 1`). `ratio < 1` refines towards
    /// `x = L`, `ratio > 1` towards `x = 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `length` or `ratio` is not finite and positive,
    /// `n_elements == 0`, `n_elements == 1` with `ratio ≠ 1`, or the grading is so extreme
    /// that node coordinates are no longer strictly increasing in floating point.
    pub fn graded(length: f64, n_elements: usize, ratio: f64) -> Result<Mesh> {
        require_positive("length", length)?;
        require_positive("ratio", ratio)?;
        if n_elements == 0 {
            return Err(Error::invalid("n_elements", n_elements, ">= 1"));
        }
        if n_elements == 1 {
            if ratio != 1.0 {
                return Err(Error::invalid(
                    "ratio",
                    ratio,
                    "= 1 for a single element (last/first element length)",
                ));
            }
            return Mesh::from_nodes(vec![0.0, length]);
        }
        let r = ratio.powf(1.0 / (n_elements as f64 - 1.0));
        let mut cum = Vec::with_capacity(n_elements + 1);
        cum.push(0.0);
        let mut h = 1.0;
        let mut s = 0.0;
        for _ in 0..n_elements {
            s += h;
            cum.push(s);
            h *= r;
        }
        let total = s;
        let nodes = cum
            .iter()
            .enumerate()
            .map(|(i, c)| {
                if i == n_elements {
                    length
                } else {
                    length * c / total
                }
            })
            .collect();
        Mesh::from_nodes(nodes)
    }

    /// Number of elements `N`.
    pub fn n_elements(&self) -> usize {
        self.nodes.len() - 1
    }

    /// Number of nodes `N + 1`.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Node coordinates `x_0 = 0, …, x_N = L`.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Length `h_e = x_{e+1} − x_e` of element `e`.
    ///
    /// # Panics
    /// If `e >= n_elements()`.
    pub fn element_length(&self, e: usize) -> f64 {
        self.nodes[e + 1] - self.nodes[e]
    }

    /// Filament length `L = x_N`.
    pub fn length(&self) -> f64 {
        self.nodes[self.nodes.len() - 1]
    }

    /// Smallest element length `min_e h_e`.
    pub fn min_element_length(&self) -> f64 {
        (0..self.n_elements())
            .map(|e| self.element_length(e))
            .fold(f64::INFINITY, f64::min)
    }

    /// The element containing `x` and the local coordinate `s = x − x_e ∈ [0, h_e]`.
    /// Interior nodes belong to the element on their right; `x = L` to the last element.
    /// `None` if `x` is not finite or outside `[0, L]`.
    pub fn locate(&self, x: f64) -> Option<(usize, f64)> {
        if !x.is_finite() || x < 0.0 || x > self.length() {
            return None;
        }
        let n_el = self.n_elements();
        let e = (self.nodes.partition_point(|&xn| xn <= x) - 1).min(n_el - 1);
        let h = self.element_length(e);
        Some((e, (x - self.nodes[e]).clamp(0.0, h)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_mesh() {
        let m = Mesh::uniform(2.0, 4).unwrap();
        assert_eq!(m.n_elements(), 4);
        assert_eq!(m.n_nodes(), 5);
        assert_eq!(m.nodes(), &[0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(m.length(), 2.0);
        assert_eq!(m.element_length(2), 0.5);
    }

    #[test]
    fn graded_mesh_ratio_and_length() {
        let m = Mesh::graded(3.0, 7, 0.2).unwrap();
        let r = m.element_length(6) / m.element_length(0);
        assert!((r - 0.2).abs() < 1e-12, "ratio {r}");
        assert_eq!(m.length(), 3.0);
        let total: f64 = (0..7).map(|e| m.element_length(e)).sum();
        assert!((total - 3.0).abs() < 1e-12);
        // consecutive ratios constant
        let q0 = m.element_length(1) / m.element_length(0);
        for e in 1..6 {
            let q = m.element_length(e + 1) / m.element_length(e);
            assert!((q - q0).abs() < 1e-12);
        }
        assert_eq!(Mesh::graded(1.0, 5, 1.0).unwrap().nodes().len(), 6);
        assert!(Mesh::graded(1.0, 1, 1.0).is_ok());
    }

    #[test]
    fn invalid_meshes_are_errors() {
        assert!(Mesh::uniform(0.0, 3).is_err());
        assert!(Mesh::uniform(f64::NAN, 3).is_err());
        assert!(Mesh::uniform(1.0, 0).is_err());
        assert!(Mesh::from_nodes(vec![0.0]).is_err());
        assert!(Mesh::from_nodes(vec![0.1, 1.0]).is_err());
        assert!(Mesh::from_nodes(vec![0.0, 0.5, 0.5, 1.0]).is_err());
        assert!(Mesh::from_nodes(vec![0.0, f64::INFINITY]).is_err());
        assert!(Mesh::graded(1.0, 4, 0.0).is_err());
        assert!(Mesh::graded(1.0, 4, -2.0).is_err());
        assert!(Mesh::graded(1.0, 1, 2.0).is_err());
        assert!(Mesh::graded(1.0, 0, 1.0).is_err());
        assert!(Mesh::graded(1.0, 3, 1e-320).is_err());
    }

    #[test]
    fn locate_points() {
        let m = Mesh::from_nodes(vec![0.0, 1.0, 3.0, 4.0]).unwrap();
        assert_eq!(m.locate(0.0), Some((0, 0.0)));
        assert_eq!(m.locate(0.5), Some((0, 0.5)));
        assert_eq!(m.locate(1.0), Some((1, 0.0)));
        assert_eq!(m.locate(2.5), Some((1, 1.5)));
        assert_eq!(m.locate(4.0), Some((2, 1.0)));
        assert_eq!(m.locate(-1e-12), None);
        assert_eq!(m.locate(4.0 + 1e-12), None);
        assert_eq!(m.locate(f64::NAN), None);
    }
}
