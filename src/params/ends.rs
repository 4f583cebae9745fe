//! The ends of a filament: each end `hinged`, `clamped` or `free`, chosen separately
//! (issue #29).
//!
//! | end       | essential (imposed) conditions | natural conditions |
//! |-----------|--------------------------------|--------------------|
//! | `hinged`  | w = 0                          | w″ = 0             |
//! | `clamped` | w = 0, w′ = 0                  | —                  |
//! | `free`    | —                              | w″ = 0, w‴ = 0     |
//!
//! The finite-element model imposes the essential conditions on its nodal degrees of
//! freedom (w and θ = w′ at the end node) and leaves the natural ones to hold weakly.
//! A filament with a free end and no clamp has rigid-body modes of zero stiffness:
//! free–free has two (translation and rotation), hinged–free one (rotation about the
//! hinge) — [`Ends::rigid_modes`].

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// One end of a filament.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum End {
    /// w = 0 imposed, w″ = 0 natural (a pin).
    Hinged,
    /// w = 0 and w′ = 0 imposed (a clamp, a grafting point).
    Clamped,
    /// Nothing imposed; w″ = w‴ = 0 natural (a free end in solution).
    Free,
}

impl End {
    /// Every end, in the order the documentation lists them.
    pub const ALL: [End; 3] = [End::Hinged, End::Clamped, End::Free];

    /// The end's name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            End::Hinged => "hinged",
            End::Clamped => "clamped",
            End::Free => "free",
        }
    }

    /// Whether the end imposes w = 0.
    pub fn fixes_deflection(self) -> bool {
        !matches!(self, End::Free)
    }

    /// Whether the end imposes w′ = 0.
    pub fn fixes_slope(self) -> bool {
        matches!(self, End::Clamped)
    }
}

impl fmt::Display for End {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for End {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        End::ALL
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| format!("`{s}` is not an end: one of hinged, clamped, free"))
    }
}

/// The two ends of a filament: `left` at x = 0, `right` at x = L.
///
/// Written `"<left>-<right>"` (e.g. `"clamped-free"`: clamped at x = 0, free at x = L);
/// a single name means both ends (`"hinged"` = `"hinged-hinged"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Ends {
    /// The end at x = 0.
    pub left: End,
    /// The end at x = L.
    pub right: End,
}

impl Default for Ends {
    /// Both ends hinged (the paper's filament).
    fn default() -> Self {
        Ends::HINGED
    }
}

impl Ends {
    /// Both ends hinged: the sine modes of eq. (3).
    pub const HINGED: Ends = Ends {
        left: End::Hinged,
        right: End::Hinged,
    };

    /// The ends `left` at x = 0 and `right` at x = L.
    pub fn new(left: End, right: End) -> Self {
        Ends { left, right }
    }

    /// Whether both ends are hinged.
    pub fn is_hinged(&self) -> bool {
        *self == Ends::HINGED
    }

    /// The number of rigid-body (zero-stiffness) modes: 2 free–free (translation and
    /// rotation), 1 hinged–free or free–hinged (rotation about the hinge), else 0
    /// (a clamp, or two hinges, fixes every rigid motion; clamped–free is a cantilever).
    pub fn rigid_modes(&self) -> usize {
        match (self.left, self.right) {
            (End::Free, End::Free) => 2,
            (End::Hinged, End::Free) | (End::Free, End::Hinged) => 1,
            _ => 0,
        }
    }

    /// The same ends seen from the other end of the filament (x → L − x).
    pub fn mirrored(&self) -> Ends {
        Ends::new(self.right, self.left)
    }

    /// Every combination of two ends, left end major.
    pub fn all() -> impl Iterator<Item = Ends> {
        End::ALL
            .into_iter()
            .flat_map(|l| End::ALL.into_iter().map(move |r| Ends::new(l, r)))
    }
}

impl fmt::Display for Ends {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}-{}", self.left, self.right)
    }
}

impl FromStr for Ends {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = |_| {
            format!(
                "`{s}` is not a pair of ends: `<left>-<right>` with each of hinged, clamped, \
                 free (e.g. `clamped-free`), or one name for both"
            )
        };
        match s.split_once('-') {
            Some((l, r)) => Ok(Ends::new(l.parse().map_err(err)?, r.parse().map_err(err)?)),
            None => {
                let e: End = s.parse().map_err(err)?;
                Ok(Ends::new(e, e))
            }
        }
    }
}

impl Serialize for Ends {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Ends {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_round_trip_through_their_names() {
        for e in Ends::all() {
            assert_eq!(e.to_string().parse::<Ends>().unwrap(), e);
        }
        assert_eq!("hinged".parse::<Ends>().unwrap(), Ends::HINGED);
        assert_eq!(
            "clamped-free".parse::<Ends>().unwrap(),
            Ends::new(End::Clamped, End::Free)
        );
        for bad in ["", "pinned", "clamped-", "free-fixed", "a-b-c"] {
            assert!(bad.parse::<Ends>().is_err(), "{bad}");
        }
        assert_eq!(Ends::all().count(), 9);
        let rigid: usize = Ends::all().map(|e| e.rigid_modes()).sum();
        assert_eq!(rigid, 2 + 1 + 1);
    }
}
