//! Our BVHs as backends: `ours`, the fast 8-wide BVH ([`WideBvh`]), and
//! the readable binary ones, `ours-sah` (binned SAH) and `ours-median`
//! (median split) ([`Bvh`]).

use super::{Answers, Backend, BackendName, BuildContext, Group, Kind, Label, TreeShape};
use crate::bvh::wide::{Kernel, UnsupportedKernel, WideBvh};
use crate::bvh::{BuildOptions, Builder, Bvh, BvhView};
use crate::geometry::TriangleMesh;
use std::time::Duration;

/// Which of our trees a kind builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tree {
    Wide,
    Binary(Builder),
}

/// One of our trees, as `--backends` names it.
struct Ours {
    label: Label<'static>,
    tree: Tree,
}

const WIDE: Ours = Ours {
    label: Label {
        name: "ours",
        aliases: &["ours-wide"],
        about: "our 8-wide BVH: parallel binned SAH, SIMD traversal (the fast path)",
    },
    tree: Tree::Wide,
};

const SAH: Ours = Ours {
    label: Label {
        name: "ours-sah",
        aliases: &[],
        about: "our binary BVH, binned SAH",
    },
    tree: Tree::Binary(Builder::Sah),
};

const MEDIAN: Ours = Ours {
    label: Label {
        name: "ours-median",
        aliases: &[],
        about: "our binary BVH, median split",
    },
    tree: Tree::Binary(Builder::Median),
};

pub(super) const KINDS: &[&dyn Kind] = &[&WIDE, &SAH, &MEDIAN];

/// `ours`: the wide BVH.
pub const OURS: BackendName = BackendName::of(&WIDE);
/// `ours-sah`.
pub const OURS_SAH: BackendName = BackendName::of(&SAH);
/// `ours-median`.
pub const OURS_MEDIAN: BackendName = BackendName::of(&MEDIAN);

fn binary_options(builder: Builder) -> BuildOptions {
    match builder {
        Builder::Sah => BuildOptions::sah(),
        Builder::Median => BuildOptions::median(),
    }
}

/// One of our trees built over a mesh: a backend, what the debug views
/// read, and the shape the course table prints.
trait OurTree: Backend + BvhView {
    fn shape(&self) -> TreeShape;
}

impl Ours {
    /// The one place our kinds choose their tree; the wide one traverses
    /// with `kernel`.
    fn tree(&self, mesh: &TriangleMesh, kernel: Kernel) -> anyhow::Result<Box<dyn OurTree>> {
        Ok(match self.tree {
            Tree::Wide => {
                let bvh = WideBvh::try_build(mesh)?;
                Box::new(bvh.with_kernel(kernel).ok_or(UnsupportedKernel(kernel))?)
            }
            Tree::Binary(builder) => Box::new(Bvh::try_build(mesh, &binary_options(builder))?),
        })
    }
}

impl Kind for Ours {
    fn label(&self) -> Label<'_> {
        self.label
    }
    fn group(&self) -> Group {
        Group::Ours
    }

    fn build(
        &self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> anyhow::Result<Box<dyn Backend>> {
        Ok(self.tree(mesh, context.kernel)?)
    }

    fn tree_shape(
        &self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> Option<anyhow::Result<TreeShape>> {
        Some(self.tree(mesh, context.kernel).map(|tree| tree.shape()))
    }

    fn bvh_view(&self, mesh: &TriangleMesh) -> Option<anyhow::Result<Box<dyn BvhView>>> {
        let tree = self.tree(mesh, Kernel::detect());
        Some(tree.map(|tree| -> Box<dyn BvhView> { tree }))
    }
}

impl OurTree for WideBvh {
    fn shape(&self) -> TreeShape {
        let stats = self.stats();
        TreeShape {
            levels: stats.levels,
            max_leaf_triangles: stats.max_leaf_triangles.to_string(),
            nodes: stats.nodes as u64,
            bytes: WideBvh::bytes(self) as u64,
            sah_cost: None,
        }
    }
}

impl OurTree for Bvh {
    fn shape(&self) -> TreeShape {
        let stats = self.stats();
        TreeShape {
            levels: stats.levels,
            max_leaf_triangles: stats.max_leaf_triangles.to_string(),
            nodes: stats.nodes as u64,
            bytes: stats.bytes as u64,
            sah_cost: Some(stats.sah_cost),
        }
    }
}

impl Backend for WideBvh {
    fn name(&self) -> String {
        OURS.to_string()
    }
    fn answers(&self) -> Answers {
        Answers::ALL
    }
    fn build_time(&self) -> Duration {
        WideBvh::build_time(self)
    }
    fn bytes(&self) -> Option<usize> {
        Some(WideBvh::bytes(self))
    }
}

impl Backend for Bvh {
    fn name(&self) -> String {
        match self.options().builder {
            Builder::Sah => OURS_SAH,
            Builder::Median => OURS_MEDIAN,
        }
        .to_string()
    }
    fn answers(&self) -> Answers {
        Answers::ALL
    }
    fn build_time(&self) -> Duration {
        self.stats().build_time
    }
    fn bytes(&self) -> Option<usize> {
        Some(self.stats().bytes)
    }
}
