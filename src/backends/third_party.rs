//! A third-party crate as a [`Kind`]: its name, one line about it and its
//! adapter's build, in the [`Group::Crate`] group.

use super::{Backend, BuildContext, Group, Kind, Label};
use crate::geometry::TriangleMesh;

/// A crate's one backend.
pub(super) struct Crate {
    pub label: Label<'static>,
    pub build: fn(&TriangleMesh) -> anyhow::Result<Box<dyn Backend>>,
}

impl Kind for Crate {
    fn label(&self) -> Label<'_> {
        self.label
    }
    fn group(&self) -> Group {
        Group::Crate
    }
    fn build(&self, mesh: &TriangleMesh, _: BuildContext) -> anyhow::Result<Box<dyn Backend>> {
        (self.build)(mesh)
    }
}
