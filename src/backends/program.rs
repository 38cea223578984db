//! Tracers run as programs: anything that reads a mesh and a rays file and
//! writes a hits file in the layout of `docs/exchange.md`, invoked as
//! `PROGRAM ARGS… MESH.ply RAYS HITS`. Such a backend answers through files,
//! in batches, not query by query: `exchange::program` records the rays a
//! command asks it, runs the program over them, and replays its answers.
//!
//! Programs of one's own are named in a tracers file ([`TracersFile`]):
//!
//! ```toml
//! [tracer.my-tracer]
//! command = ["./build/my_tracer", "--bvh", "sah"]  # relative to this file's folder
//! about = "my tracer's SAH BVH"                     # optional
//! batch_rays = 1000000                              # optional: rays per file
//! timeout_seconds = 600                             # optional: per batch
//! slow = false                                      # optional: the standard report
//!                                                   # runs a slow one on fewer scenes
//! ```

use super::{Backend, BuildContext, Group, Kind, Label};
use crate::adapters::{Adapter, ProgramCommand, SetupError};
use crate::geometry::TriangleMesh;
use serde::Deserialize;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::Path;
use std::time::Duration;

/// Rays in one batch, unless a program says otherwise.
pub const DEFAULT_BATCH_RAYS: usize = 1 << 20;

/// How long one batch may take, unless a program says otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(600);

/// A tracer of `adapters/`, with the default batch size and timeout.
const fn bundled(
    adapter: Adapter,
    name: &'static str,
    about: &'static str,
    slow: bool,
) -> ProgramKind {
    ProgramKind {
        name: Cow::Borrowed(name),
        about: Cow::Borrowed(about),
        launch: Launch::Adapter(adapter),
        batch_rays: DEFAULT_BATCH_RAYS,
        timeout: DEFAULT_TIMEOUT,
        slow,
    }
}

const MITSUBA_SCALAR: ProgramKind = bundled(
    Adapter::MitsubaScalar,
    "mitsuba-scalar",
    "Mitsuba 3.9, scalar_rgb variant (one ray per call; its wheel traces with Embree 3.13)",
    false,
);

const MITSUBA_LLVM: ProgramKind = bundled(
    Adapter::MitsubaLlvm,
    "mitsuba-llvm",
    "Mitsuba 3.9, llvm_ad_rgb variant (vectorised; its wheel traces with Embree 3.13)",
    false,
);

const TRIMESH: ProgramKind = bundled(
    Adapter::Trimesh,
    "trimesh",
    "trimesh 5.2's pure-numpy ray_triangle intersector, with an r-tree",
    true,
);

const CPP_TEMPLATE: ProgramKind = bundled(
    Adapter::CppTemplate,
    "cpp-template",
    "the C++ template for a tracer of one's own (brute force in its place)",
    true,
);

/// The tracers of `adapters/`.
pub(super) const KINDS: &[&dyn Kind] = &[&MITSUBA_SCALAR, &MITSUBA_LLVM, &TRIMESH, &CPP_TEMPLATE];

/// A tracer run as a program.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramKind {
    name: Cow<'static, str>,
    about: Cow<'static, str>,
    /// How it is started; the three file paths are appended.
    pub launch: Launch,
    /// The most rays one file of a batch holds.
    pub batch_rays: usize,
    /// How long one batch may run before the program is stopped.
    pub timeout: Duration,
    /// Whether it traces so slowly (one ray per call of an interpreted
    /// language, say) that the standard report runs it on the quick
    /// scenes only.
    pub slow: bool,
}

/// How a program is started.
#[derive(Clone, Debug, PartialEq)]
pub enum Launch {
    /// A tracer of `adapters/`, set up in the cache on first use.
    Adapter(Adapter),
    /// A program a tracers file names, as it is.
    Command(ProgramCommand),
}

impl Launch {
    /// The command that runs the program, once what it needs is set up
    /// under `cache`.
    pub fn prepare(&self, cache: &Path) -> Result<ProgramCommand, SetupError> {
        match self {
            Launch::Adapter(adapter) => adapter.prepare(cache),
            Launch::Command(command) => Ok(command.clone()),
        }
    }
}

impl ProgramKind {
    /// The name `--backends` takes for it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A program named `name` run as `command`, with the default batch
    /// size and timeout.
    pub fn new(name: &str, about: &str, command: ProgramCommand) -> Self {
        Self {
            name: Cow::Owned(name.to_string()),
            about: Cow::Owned(about.to_string()),
            launch: Launch::Command(command),
            batch_rays: DEFAULT_BATCH_RAYS,
            timeout: DEFAULT_TIMEOUT,
            slow: false,
        }
    }
}

impl Kind for ProgramKind {
    fn label(&self) -> Label<'_> {
        Label {
            name: &self.name,
            aliases: &[],
            about: &self.about,
        }
    }
    fn group(&self) -> Group {
        Group::Program
    }

    /// Refused: a program answers through files (see the module's note).
    fn build(&self, _: &TriangleMesh, _: BuildContext) -> anyhow::Result<Box<dyn Backend>> {
        anyhow::bail!(
            "{} is a program: it answers rays in batches through files, in compare, \
             stability, trace and the report, not query by query",
            self.name
        )
    }

    fn program(&self) -> Option<&ProgramKind> {
        Some(self)
    }
}

/// A tracers file: `[tracer.NAME]` tables, each a program.
pub struct TracersFile {
    pub programs: Vec<ProgramKind>,
}

/// One `[tracer.NAME]` table as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TracerTable {
    command: Vec<String>,
    about: Option<String>,
    batch_rays: Option<usize>,
    timeout_seconds: Option<f64>,
    slow: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TracersTable {
    #[serde(default)]
    tracer: BTreeMap<String, TracerTable>,
}

impl TracersFile {
    /// Reads the tracers file at `path`. A command's program with a folder
    /// in it (`./build/tracer`) is taken relative to the file's folder; a
    /// bare name (`python3`) is looked up on `PATH` when it runs.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            anyhow::anyhow!("{}: cannot read the tracers file: {e}", path.display())
        })?;
        Self::parse(path, &text)
    }

    /// The tracers file `text`, read from `path`.
    pub fn parse(path: &Path, text: &str) -> anyhow::Result<Self> {
        let table: TracersTable = toml::from_str(text)
            .map_err(|e| anyhow::anyhow!("{}: not a tracers file: {e}", path.display()))?;
        let folder = path.parent().unwrap_or(Path::new("."));
        let mut programs = Vec::new();
        for (name, tracer) in table.tracer {
            let at = || format!("{}: [tracer.{name}]", path.display());
            anyhow::ensure!(
                !name.is_empty() && !name.contains([',', ' ']),
                "{}: a tracer's name may hold no comma or space",
                at()
            );
            let Some((program, args)) = tracer.command.split_first() else {
                anyhow::bail!("{}: `command` is empty: give the program to run", at());
            };
            let program = Path::new(program);
            let program = if program.components().count() > 1 && program.is_relative() {
                folder.join(program)
            } else {
                program.to_path_buf()
            };
            let command = ProgramCommand {
                program,
                args: args.iter().map(OsString::from).collect(),
            };
            let about = tracer
                .about
                .unwrap_or_else(|| format!("the program {}", command.program.display()));
            let mut kind = ProgramKind::new(&name, &about, command);
            if let Some(rays) = tracer.batch_rays {
                anyhow::ensure!(rays > 0, "{}: `batch_rays` must be at least 1", at());
                kind.batch_rays = rays;
            }
            if let Some(seconds) = tracer.timeout_seconds {
                kind.timeout = Duration::try_from_secs_f64(seconds)
                    .ok()
                    .filter(|t| !t.is_zero())
                    .ok_or_else(|| {
                        anyhow::anyhow!("{}: `timeout_seconds` must be above 0", at())
                    })?;
            }
            kind.slow = tracer.slow.unwrap_or(false);
            programs.push(kind);
        }
        Ok(Self { programs })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tracers_file_names_programs_relative_to_its_folder() {
        let file = TracersFile::parse(
            Path::new("/project/tracers.toml"),
            "[tracer.mine]\ncommand = [\"./bin/trace\", \"--fast\"]\nbatch_rays = 10\n\
             timeout_seconds = 2.5\n[tracer.py]\ncommand = [\"python3\", \"t.py\"]\n",
        )
        .unwrap();
        let [mine, py] = &file.programs[..] else {
            panic!("two programs")
        };
        assert_eq!(mine.name(), "mine");
        let Launch::Command(command) = &mine.launch else {
            panic!("a command")
        };
        assert_eq!(command.program, Path::new("/project/./bin/trace"));
        assert_eq!(command.args, ["--fast"]);
        assert_eq!(
            (mine.batch_rays, mine.timeout),
            (10, Duration::from_secs_f64(2.5))
        );
        assert_eq!(
            py.launch,
            Launch::Command(ProgramCommand {
                program: "python3".into(),
                args: vec!["t.py".into()],
            })
        );
        assert_eq!(py.timeout, DEFAULT_TIMEOUT);
        assert_eq!(py.group(), Group::Program);
    }

    #[test]
    fn a_bad_tracers_file_says_where() {
        let path = Path::new("t.toml");
        for (text, expected) in [
            (
                "[tracer.x]\ncommand = []\n",
                "t.toml: [tracer.x]: `command` is empty",
            ),
            ("[tracer.x]\n", "t.toml: not a tracers file"),
            (
                "[tracer.x]\ncommand = [\"a\"]\nbatch_rays = 0\n",
                "`batch_rays` must be at least 1",
            ),
            (
                "[tracer.x]\ncommand = [\"a\"]\ntimeout_seconds = -1\n",
                "`timeout_seconds` must be above 0",
            ),
            (
                "[tracer.x]\ncommand = [\"a\"]\ncolour = 1\n",
                "unknown field",
            ),
            ("[tracer.\"a,b\"]\ncommand = [\"a\"]\n", "no comma or space"),
        ] {
            let error = TracersFile::parse(path, text).err().unwrap().to_string();
            assert!(error.contains(expected), "{text}: {error}");
        }
    }
}
