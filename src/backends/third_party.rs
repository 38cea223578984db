//! A third-party crate as a [`Kind`]: its name, one line about it and its
//! adapter's build, in the [`Group::Crate`] group.

use super::{Backend, BuildContext, Group, Kind};
use crate::geometry::TriangleMesh;

/// A crate's one backend.
pub(super) struct Crate {
    pub name: &'static str,
    pub about: &'static str,
    pub build: fn(&TriangleMesh) -> anyhow::Result<Box<dyn Backend>>,
}

impl Kind for Crate {
    fn name(&self) -> &'static str {
        self.name
    }
    fn group(&self) -> Group {
        Group::Crate
    }
    fn about(&self) -> &'static str {
        self.about
    }
    fn build(&self, mesh: &TriangleMesh, _: BuildContext) -> anyhow::Result<Box<dyn Backend>> {
        (self.build)(mesh)
    }
}
