//! The one list of every backend `--backends` can name, and the names
//! parsed from it.
//!
//! Adding a backend is its file, with its [`Kind`]s, and one line in
//! `FILES`: the names `--backends` takes, the help and error texts, the
//! groups the commands and the report read and `raycheck backends` all
//! come from here (as pbrt-v4's one `Shape::Create` factory over a table).
//! A [`Registry`] adds the programs of a tracers file to those built in.

use super::program::{ProgramKind, TracersFile};
use super::{Backend, BuildContext, Group, Kind, TreeShape};
use crate::bvh::BvhView;
use crate::geometry::TriangleMesh;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::path::Path;
use std::str::FromStr;
use std::sync::Arc;

/// Every backend file's kinds, in the order help lists them.
const FILES: [&[&dyn Kind]; 6] = [
    super::ours::KINDS,
    super::embree::KINDS,
    super::obvhs::KINDS,
    super::bvh_crate::KINDS,
    super::parry3d::KINDS,
    super::program::KINDS,
];

/// The backends `--backends` defaults to: ours, checked against Embree
/// and Embree robust.
pub const DEFAULT_BACKENDS: &str = "ours,embree,embree-robust";

/// A backend as `--backends` names it: one of the registry's kinds.
/// Names compare, hash and print by their `--backends` spelling.
#[derive(Clone)]
pub struct BackendName(KindRef);

/// A kind built in (a static of its file) or made at run time (a program
/// of a tracers file, or a stand-in a command makes for one).
#[derive(Clone)]
enum KindRef {
    Static(&'static dyn Kind),
    Shared(Arc<dyn Kind + Send>),
}

impl BackendName {
    /// The name of `kind`, for the constants each backend file exports.
    pub const fn of(kind: &'static dyn Kind) -> Self {
        Self(KindRef::Static(kind))
    }

    /// The name of a kind made at run time.
    pub fn shared(kind: Arc<dyn Kind + Send>) -> Self {
        Self(KindRef::Shared(kind))
    }

    fn kind(&self) -> &dyn Kind {
        match &self.0 {
            KindRef::Static(kind) => *kind,
            KindRef::Shared(kind) => kind.as_ref(),
        }
    }

    /// Every built-in backend, in the registry's order.
    pub fn all() -> impl Iterator<Item = BackendName> {
        FILES
            .into_iter()
            .flatten()
            .map(|&kind| BackendName::of(kind))
    }

    /// Every built-in backend of `group`, in the registry's order.
    pub fn in_group(group: Group) -> Vec<BackendName> {
        Self::all().filter(|name| name.group() == group).collect()
    }

    /// [`DEFAULT_BACKENDS`], parsed.
    pub fn defaults() -> Vec<BackendName> {
        Self::parse_list(DEFAULT_BACKENDS).expect("the default backends are registered")
    }

    /// Parses a comma-separated list of built-in names such as
    /// `ours,embree,embree-robust` (see [`Registry::parse_list`]).
    pub fn parse_list(list: &str) -> Result<Vec<BackendName>, UnknownBackend> {
        Registry::built_in().parse_list(list)
    }

    pub fn as_str(&self) -> &str {
        self.kind().label().name
    }

    pub fn group(&self) -> Group {
        self.kind().group()
    }

    pub fn about(&self) -> &str {
        self.kind().label().about
    }

    /// Whether it is a third-party tracer (see [`Group::is_third_party`]).
    pub fn is_third_party(&self) -> bool {
        self.group().is_third_party()
    }

    /// The program it runs, for a tracer run as a program.
    pub fn program(&self) -> Option<&ProgramKind> {
        self.kind().program()
    }

    /// Builds the backend over `mesh`.
    pub fn build(
        &self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> anyhow::Result<Box<dyn Backend>> {
        self.kind().build(mesh, context)
    }

    /// See [`Kind::tree_shape`].
    pub fn tree_shape(
        &self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> Option<anyhow::Result<TreeShape>> {
        self.kind().tree_shape(mesh, context)
    }

    /// See [`Kind::bvh_view`].
    pub fn bvh_view(&self, mesh: &TriangleMesh) -> Option<anyhow::Result<Box<dyn BvhView>>> {
        self.kind().bvh_view(mesh)
    }

    /// What `--backends` takes, for its help: the default, then every
    /// built-in name by group.
    pub fn help() -> String {
        let mut text = format!(
            "Comma-separated backends, the first the one checked (default: {DEFAULT_BACKENDS})."
        );
        let names: Vec<BackendName> = Self::all().collect();
        for group in groups(&names) {
            let names: Vec<&str> = names
                .iter()
                .filter(|n| n.group() == group)
                .map(|n| n.as_str())
                .collect();
            text += &format!(" {}: {}.", capitalized(group.title()), names.join(", "));
        }
        text + " A tracers file (--tracers) adds programs of one's own."
    }
}

/// The groups of `names`, in order.
fn groups(names: &[BackendName]) -> Vec<Group> {
    let mut groups: Vec<Group> = names.iter().map(BackendName::group).collect();
    groups.sort();
    groups.dedup();
    groups
}

/// Every backend a run can name: those built in, and the programs of a
/// tracers file.
#[derive(Clone)]
pub struct Registry {
    names: Vec<BackendName>,
}

impl Registry {
    /// The built-in backends.
    pub fn built_in() -> Self {
        Self {
            names: BackendName::all().collect(),
        }
    }

    /// The built-in backends and the programs of the tracers file at
    /// `path`, when given (see [`TracersFile`]); a program may not take a
    /// name already taken.
    pub fn with_tracers(path: Option<&Path>) -> anyhow::Result<Self> {
        let mut registry = Self::built_in();
        let Some(path) = path else {
            return Ok(registry);
        };
        for program in TracersFile::load(path)?.programs {
            let name = program.name().to_string();
            anyhow::ensure!(
                registry.find(&name).is_none(),
                "{}: tracer '{name}' takes the name of a built-in backend",
                path.display()
            );
            registry.names.push(BackendName::shared(Arc::new(program)));
        }
        Ok(registry)
    }

    /// Every backend, built in first.
    pub fn names(&self) -> &[BackendName] {
        &self.names
    }

    fn find(&self, text: &str) -> Option<BackendName> {
        self.names
            .iter()
            .find(|name| name.as_str() == text || name.kind().label().aliases.contains(&text))
            .cloned()
    }

    /// Parses a comma-separated list such as `ours,embree,embree-robust`.
    pub fn parse_list(&self, list: &str) -> Result<Vec<BackendName>, UnknownBackend> {
        let names: Vec<BackendName> = list
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|text| self.parse(text))
            .collect::<Result<_, _>>()?;
        if names.is_empty() {
            return Err(UnknownBackend {
                name: list.to_string(),
                known: self.known_names(),
            });
        }
        Ok(names)
    }

    /// One name.
    pub fn parse(&self, text: &str) -> Result<BackendName, UnknownBackend> {
        self.find(text).ok_or_else(|| UnknownBackend {
            name: text.to_string(),
            known: self.known_names(),
        })
    }

    fn known_names(&self) -> String {
        let names: Vec<&str> = self.names.iter().map(BackendName::as_str).collect();
        names.join(", ")
    }
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
#[error("unknown backend '{name}': expected one of {known}")]
pub struct UnknownBackend {
    pub name: String,
    /// Every name the registry knows, comma-separated.
    pub known: String,
}

impl FromStr for BackendName {
    type Err = UnknownBackend;

    /// A built-in name.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Registry::built_in().parse(text)
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
            for alias in name.kind().label().aliases {
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
        assert_eq!(error.name, "optix");
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
