//! The one list of every backend `--backends` can name, and the names
//! parsed from it.
//!
//! Adding a backend is its file, with its [`Kind`]s, and one line in
//! [`FILES`]: the names `--backends` takes, the help and error texts, the
//! groups the commands and the report read and `raycheck backends` all
//! come from here (as pbrt-v4's one `Shape::Create` factory over a table).

use super::{Backend, BuildContext, Group, Kind, TreeShape};
use crate::bvh::BvhView;
use crate::geometry::TriangleMesh;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::str::FromStr;

/// Every backend file's kinds, in the order help lists them.
const FILES: [&[&dyn Kind]; 5] = [
    super::ours::KINDS,
    super::embree::KINDS,
    super::obvhs::KINDS,
    super::bvh_crate::KINDS,
    super::parry3d::KINDS,
];

/// The backends `--backends` defaults to: ours, checked against Embree
/// and Embree robust.
pub const DEFAULT_BACKENDS: &str = "ours,embree,embree-robust";

/// A backend as `--backends` names it: one of the registry's kinds.
/// Names compare, hash and print by their `--backends` spelling.
#[derive(Clone, Copy)]
pub struct BackendName(&'static dyn Kind);

impl BackendName {
    /// The name of `kind`, for the constants each backend file exports.
    pub const fn of(kind: &'static dyn Kind) -> Self {
        Self(kind)
    }

    /// Every backend, in the registry's order.
    pub fn all() -> impl Iterator<Item = BackendName> {
        FILES.into_iter().flatten().map(|&kind| BackendName(kind))
    }

    /// Every backend of `group`, in the registry's order.
    pub fn in_group(group: Group) -> Vec<BackendName> {
        Self::all().filter(|name| name.group() == group).collect()
    }

    /// [`DEFAULT_BACKENDS`], parsed.
    pub fn defaults() -> Vec<BackendName> {
        Self::parse_list(DEFAULT_BACKENDS).expect("the default backends are registered")
    }

    /// Parses a comma-separated list such as `ours,embree,embree-robust`.
    pub fn parse_list(list: &str) -> Result<Vec<BackendName>, UnknownBackend> {
        let names: Vec<BackendName> = list
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        if names.is_empty() {
            return Err(UnknownBackend(list.to_string()));
        }
        Ok(names)
    }

    pub fn as_str(self) -> &'static str {
        self.0.name()
    }

    pub fn group(self) -> Group {
        self.0.group()
    }

    pub fn about(self) -> &'static str {
        self.0.about()
    }

    /// Whether it is a third-party tracer (see [`Group::is_third_party`]).
    pub fn is_third_party(self) -> bool {
        self.group().is_third_party()
    }

    /// Builds the backend over `mesh`.
    pub fn build(
        self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> anyhow::Result<Box<dyn Backend>> {
        self.0.build(mesh, context)
    }

    /// See [`Kind::tree_shape`].
    pub fn tree_shape(
        self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> Option<anyhow::Result<TreeShape>> {
        self.0.tree_shape(mesh, context)
    }

    /// See [`Kind::bvh_view`].
    pub fn bvh_view(self, mesh: &TriangleMesh) -> Option<anyhow::Result<Box<dyn BvhView>>> {
        self.0.bvh_view(mesh)
    }

    /// What `--backends` takes, for its help: the default, then every name
    /// by group.
    pub fn help() -> String {
        let mut text = format!(
            "Comma-separated backends, the first the one checked (default: {DEFAULT_BACKENDS})."
        );
        for group in groups() {
            let names: Vec<&str> = Self::in_group(group).iter().map(|n| n.as_str()).collect();
            text += &format!(" {}: {}.", capitalized(group.title()), names.join(", "));
        }
        text
    }
}

/// The groups that have backends, in order.
fn groups() -> Vec<Group> {
    let mut groups: Vec<Group> = BackendName::all().map(BackendName::group).collect();
    groups.sort();
    groups.dedup();
    groups
}

fn capitalized(text: &str) -> String {
    let mut chars = text.chars();
    chars
        .next()
        .map(|first| first.to_uppercase().chain(chars).collect())
        .unwrap_or_default()
}

impl PartialEq for BackendName {
    fn eq(&self, other: &Self) -> bool {
        self.as_str() == other.as_str()
    }
}

impl Eq for BackendName {}

impl Hash for BackendName {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.as_str().hash(state);
    }
}

impl fmt::Display for BackendName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl fmt::Debug for BackendName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A name `--backends` does not know; its message lists every name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown backend '{0}': expected one of {names}", names = known_names())]
pub struct UnknownBackend(pub String);

fn known_names() -> String {
    let names: Vec<&str> = BackendName::all().map(BackendName::as_str).collect();
    names.join(", ")
}

impl FromStr for BackendName {
    type Err = UnknownBackend;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Self::all()
            .find(|name| name.as_str() == text || name.0.aliases().contains(&text))
            .ok_or_else(|| UnknownBackend(text.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backends::embree::{EMBREE, EMBREE_ROBUST};
    use crate::backends::ours::OURS;

    #[test]
    fn every_name_round_trips_and_is_unique() {
        let names: Vec<BackendName> = BackendName::all().collect();
        for (i, name) in names.iter().enumerate() {
            assert_eq!(name.as_str().parse::<BackendName>().unwrap(), *name);
            assert!(!names[..i].contains(name), "{name} registered twice");
            for alias in name.0.aliases() {
                assert_eq!(alias.parse::<BackendName>().unwrap(), *name);
            }
        }
        assert_eq!(
            "embree-medium".parse::<BackendName>().unwrap().as_str(),
            "embree"
        );
    }

    #[test]
    fn lists_parse_and_unknown_names_are_named() {
        assert_eq!(BackendName::defaults(), [OURS, EMBREE, EMBREE_ROBUST]);
        let error = BackendName::parse_list("ours,optix").unwrap_err();
        assert_eq!(error, UnknownBackend("optix".into()));
        let message = error.to_string();
        for name in BackendName::all() {
            assert!(message.contains(name.as_str()), "{message}");
        }
        assert!(BackendName::parse_list(" , ").is_err());
    }

    #[test]
    fn help_names_every_backend_under_its_group() {
        let help = BackendName::help();
        for name in BackendName::all() {
            assert!(help.contains(name.as_str()), "{help}");
        }
        assert!(help.contains("Third-party crates: obvhs, bvh, parry3d."));
    }
}
