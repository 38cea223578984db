//! Every tracer the harness can check, behind one trait.
//!
//! A [`Backend`] is an [`Intersector`] built over one triangle mesh that
//! also says who it is, which parts of an answer it gives ([`Answers`]),
//! how long its build took and how much memory it holds. [`BackendName`]
//! is what `--backends` parses; [`BackendName::build`] is the one factory
//! every subcommand builds its backends with.
//!
//! - `ours` (the fast wide BVH), `ours-sah`, `ours-median`: [`crate::bvh`];
//! - `embree`, `embree-robust`, `embree-low`, `embree-high[-robust]`, …:
//!   Embree 4.4 through `raycheck_reference` ([`embree`]);
//! - `obvhs`: the obvhs crate's CWBVH ([`obvhs`](self::obvhs));
//! - `bvh`: svenstaro's `bvh` crate ([`bvh_crate`]);
//! - `parry3d`: parry3d's `TriMesh` ray casts ([`parry3d`](self::parry3d)).

pub mod bvh_crate;
pub mod embree;
mod guard;
pub mod obvhs;
pub mod parry3d;

use crate::bvh::wide::{Kernel, UnsupportedKernel, WideBvh};
use crate::bvh::{BuildOptions, Bvh};
use crate::geometry::TriangleMesh;
use crate::trace::Intersector;
use raycheck_reference::{BuildQuality, Device, DeviceConfig, Isa, SceneOptions};
use serde::Serialize;
use std::fmt;
use std::str::FromStr;
use std::time::Duration;

/// Which parts of an answer a backend gives. Every backend gives a hit's
/// distance `t` and triangle index, and answers any-hit queries (natively
/// or through its closest hit, as its adapter documents). The referee
/// judges the parts given; tables print "n/a" for the others, never
/// counting them right or wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Answers {
    /// Barycentric `u`, `v` of a hit, in Embree's convention (`u` weights
    /// the second vertex, `v` the third).
    pub uv: bool,
    /// The geometric normal of the hit triangle.
    pub normal: bool,
}

impl Answers {
    /// Everything: `t`, triangle, `u`, `v` and the normal.
    pub const ALL: Answers = Answers {
        uv: true,
        normal: true,
    };
}

/// A tracer built over one mesh, ready to answer queries.
pub trait Backend: Intersector + Send {
    /// The name `--backends` takes for it, e.g. `ours` or `embree-robust`.
    fn name(&self) -> String;
    /// Which parts of an answer it gives.
    fn answers(&self) -> Answers;
    /// Wall time of its build.
    fn build_time(&self) -> Duration;
    /// Bytes its acceleration structure holds, where that can be known.
    fn bytes(&self) -> Option<usize>;
}

/// A backend as `--backends` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BackendName {
    /// Our BVH: `ours` (the wide BVH), `ours-sah`, `ours-median`.
    Ours(OurBuilder),
    /// Embree 4.4: `embree[-low|-medium|-high][-robust]`.
    Embree(SceneOptions),
    /// The obvhs crate's CWBVH: `obvhs`.
    Obvhs,
    /// svenstaro's `bvh` crate: `bvh`.
    BvhCrate,
    /// parry3d's `TriMesh`: `parry3d`.
    Parry3d,
}

/// Which of our builders a backend uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OurBuilder {
    /// The fast wide BVH ([`WideBvh`]), traversed with the fastest kernel
    /// the CPU runs.
    Wide,
    /// The wide BVH traversed with this kernel (`--kernel`); named `ours`
    /// too, since every kernel gives the same answers.
    WideKernel(Kernel),
    /// The binary binned-SAH BVH.
    Sah,
    /// The binary median-split BVH.
    Median,
}

impl OurBuilder {
    /// The binary builder's options; `None` for the wide BVH.
    pub fn binary_options(self) -> Option<BuildOptions> {
        match self {
            OurBuilder::Wide | OurBuilder::WideKernel(_) => None,
            OurBuilder::Sah => Some(BuildOptions::sah()),
            OurBuilder::Median => Some(BuildOptions::median()),
        }
    }
}

/// The backends `--backends` defaults to: ours, Embree, Embree robust.
pub const DEFAULT_BACKENDS: &str = "ours,embree,embree-robust";

/// Embree's configuration that checks ours by default: MEDIUM with
/// `RTC_SCENE_FLAG_ROBUST`, watertight like ours.
pub const EMBREE_ROBUST: SceneOptions = SceneOptions {
    quality: BuildQuality::Medium,
    robust: true,
};

/// Embree's default configuration: MEDIUM, not robust.
pub const EMBREE_MEDIUM: SceneOptions = SceneOptions {
    quality: BuildQuality::Medium,
    robust: false,
};

/// The Embree device every Embree backend of a run is built on, with
/// `threads` build threads, no statistics output and the widest
/// instruction set Embree and the CPU have.
pub fn embree_device(threads: usize) -> anyhow::Result<Device> {
    embree_device_with_isa(threads, Isa::Auto)
}

/// [`embree_device`] with Embree's kernels limited to `isa`.
pub fn embree_device_with_isa(threads: usize, isa: Isa) -> anyhow::Result<Device> {
    Ok(Device::new(&DeviceConfig {
        threads: Some(threads),
        verbose: 0,
        isa,
    })?)
}

impl BackendName {
    /// Builds this backend over `mesh`; Embree's go on `device`.
    pub fn build(self, mesh: &TriangleMesh, device: &Device) -> anyhow::Result<Box<dyn Backend>> {
        Ok(match self {
            BackendName::Ours(OurBuilder::WideKernel(kernel)) => {
                let bvh = WideBvh::try_build(mesh)?;
                Box::new(bvh.with_kernel(kernel).ok_or(UnsupportedKernel(kernel))?)
            }
            BackendName::Ours(builder) => match builder.binary_options() {
                None => Box::new(WideBvh::try_build(mesh)?),
                Some(options) => Box::new(Bvh::try_build(mesh, &options)?),
            },
            BackendName::Embree(options) => Box::new(embree::build_scene(device, mesh, options)?),
            BackendName::Obvhs => Box::new(self::obvhs::ObvhsBackend::build(mesh)?),
            BackendName::BvhCrate => Box::new(bvh_crate::BvhCrateBackend::build(mesh)?),
            BackendName::Parry3d => Box::new(self::parry3d::Parry3dBackend::build(mesh)?),
        })
    }

    /// The kernel our wide BVH runs with as this backend; `None` for any
    /// other backend.
    pub fn kernel(self) -> Option<Kernel> {
        match self {
            BackendName::Ours(OurBuilder::Wide) => Some(Kernel::detect()),
            BackendName::Ours(OurBuilder::WideKernel(kernel)) => Some(kernel),
            _ => None,
        }
    }

    /// Whether the backend is a third-party crate (not ours, not Embree).
    pub fn is_third_party(self) -> bool {
        matches!(
            self,
            BackendName::Obvhs | BackendName::BvhCrate | BackendName::Parry3d
        )
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
}

impl fmt::Display for BackendName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BackendName::Ours(OurBuilder::Wide | OurBuilder::WideKernel(_)) => f.write_str("ours"),
            BackendName::Ours(OurBuilder::Sah) => f.write_str("ours-sah"),
            BackendName::Ours(OurBuilder::Median) => f.write_str("ours-median"),
            BackendName::Embree(options) => f.write_str(&embree::name(*options)),
            BackendName::Obvhs => f.write_str("obvhs"),
            BackendName::BvhCrate => f.write_str("bvh"),
            BackendName::Parry3d => f.write_str("parry3d"),
        }
    }
}

/// A name `--backends` does not know.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown backend '{0}': expected ours, ours-sah, ours-median, \
     embree[-low|-medium|-high][-robust], obvhs, bvh, parry3d"
)]
pub struct UnknownBackend(pub String);

impl FromStr for BackendName {
    type Err = UnknownBackend;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let unknown = || UnknownBackend(text.to_string());
        Ok(match text {
            "ours" | "ours-wide" => BackendName::Ours(OurBuilder::Wide),
            "ours-sah" => BackendName::Ours(OurBuilder::Sah),
            "ours-median" => BackendName::Ours(OurBuilder::Median),
            "obvhs" => BackendName::Obvhs,
            "bvh" => BackendName::BvhCrate,
            "parry3d" => BackendName::Parry3d,
            _ => BackendName::Embree(embree::parse_name(text).ok_or_else(unknown)?),
        })
    }
}

impl Backend for WideBvh {
    fn name(&self) -> String {
        BackendName::Ours(OurBuilder::Wide).to_string()
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
        let builder = match self.options().builder {
            crate::bvh::Builder::Sah => OurBuilder::Sah,
            crate::bvh::Builder::Median => OurBuilder::Median,
        };
        BackendName::Ours(builder).to_string()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for name in [
            "ours",
            "ours-sah",
            "ours-median",
            "embree",
            "embree-robust",
            "embree-low",
            "embree-high-robust",
            "obvhs",
            "bvh",
            "parry3d",
        ] {
            let parsed: BackendName = name.parse().unwrap();
            assert_eq!(parsed.to_string(), name);
        }
        assert_eq!(
            "embree-medium".parse::<BackendName>().unwrap().to_string(),
            "embree"
        );
    }

    #[test]
    fn lists_parse_and_unknown_names_are_named() {
        let list = BackendName::parse_list(DEFAULT_BACKENDS).unwrap();
        assert_eq!(
            list,
            [
                BackendName::Ours(OurBuilder::Wide),
                BackendName::Embree(EMBREE_MEDIUM),
                BackendName::Embree(EMBREE_ROBUST)
            ]
        );
        let error = BackendName::parse_list("ours,optix").unwrap_err();
        assert_eq!(error, UnknownBackend("optix".into()));
        assert!(BackendName::parse_list(" , ").is_err());
    }
}
