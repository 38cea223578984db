//! One command's rays for the programs among its backends: the meshes and
//! rays each program is asked, recorded while the command runs without it
//! (a stand-in answers as the checked backend does), and its answers,
//! replayed when the command runs again.

use crate::backends::{
    Answers, Backend, BackendName, BuildContext, Group, Kind, Label, ProgramKind,
};
use crate::check::{Answer, ray_bits};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A mesh by its content: every bit of its positions and indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MeshKey(u64);

impl MeshKey {
    pub fn of(mesh: &TriangleMesh) -> Self {
        let mut hasher = DefaultHasher::new();
        for p in &mesh.positions {
            p.to_array().map(f32::to_bits).hash(&mut hasher);
        }
        mesh.indices.hash(&mut hasher);
        Self(hasher.finish())
    }
}

/// What a program is asked of one mesh: its closest-hit and its any-hit
/// rays, each once, in the order first asked.
#[derive(Default)]
pub struct Asked {
    pub closest: Vec<Ray>,
    pub any_hit: Vec<Ray>,
    seen_closest: std::collections::HashSet<[u32; 8]>,
    seen_any_hit: std::collections::HashSet<[u32; 8]>,
}

impl Asked {
    fn ask(&mut self, ray: &Ray, any_hit: bool) {
        let (seen, rays) = if any_hit {
            (&mut self.seen_any_hit, &mut self.any_hit)
        } else {
            (&mut self.seen_closest, &mut self.closest)
        };
        if seen.insert(ray_bits(ray)) {
            rays.push(*ray);
        }
    }
}

/// A program's answers on one mesh, by the bits of their rays.
#[derive(Default)]
pub struct Answered {
    pub closest: HashMap<[u32; 8], Option<Hit>>,
    pub any_hit: HashMap<[u32; 8], bool>,
    /// Whether the program gave `u`, `v` (every batch said so).
    pub gives_uv: bool,
}

/// The rays one mesh is asked, shared by the stand-ins built over it.
pub type SharedAsked = Arc<Mutex<Asked>>;

/// Everything one program was asked, and then answered.
#[derive(Default)]
pub struct ProgramRecord {
    /// Each mesh asked of, with its rays, in the order first built over.
    pub meshes: Vec<(MeshKey, TriangleMesh, SharedAsked)>,
    pub answers: HashMap<MeshKey, Arc<Answered>>,
    /// Rays asked on replay that were never recorded: none, unless the
    /// command asked other rays the second time.
    pub unrecorded: Arc<AtomicU64>,
}

/// The record of one program, shared by its stand-ins.
pub type SharedRecord = Arc<Mutex<ProgramRecord>>;

fn lock<T>(shared: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    shared
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Stands in for a program while a command first runs: it answers as
/// `checked` does, so nothing it answers is counted, and records every
/// mesh and ray it is asked.
pub struct Recording {
    pub program: ProgramKind,
    pub checked: BackendName,
    pub record: SharedRecord,
}

/// Answers for a program when the command runs again, from what it wrote.
pub struct Replaying {
    pub program: ProgramKind,
    pub record: SharedRecord,
}

impl Kind for Recording {
    fn label(&self) -> Label<'_> {
        self.program.label()
    }
    fn group(&self) -> Group {
        Group::Program
    }
    fn build(
        &self,
        mesh: &TriangleMesh,
        context: BuildContext,
    ) -> anyhow::Result<Box<dyn Backend>> {
        can_be_handed(&self.program, mesh)?;
        let key = MeshKey::of(mesh);
        let asked = {
            let mut record = lock(&self.record);
            match record.meshes.iter().find(|(k, _, _)| *k == key) {
                Some((_, _, asked)) => Arc::clone(asked),
                None => {
                    let asked = SharedAsked::default();
                    record.meshes.push((key, mesh.clone(), Arc::clone(&asked)));
                    asked
                }
            }
        };
        Ok(Box::new(RecordingBackend {
            name: self.program.name().to_string(),
            inner: self.checked.build(mesh, context)?,
            asked,
        }))
    }
}

/// Refuses a mesh the files cannot carry to a program: one with a NaN or
/// infinite vertex, which every mesh reader (raycheck's and the
/// adapters') refuses as bad input. The program is then counted as not
/// built over that mesh, as a crate that refuses it is, and runs on the
/// others.
fn can_be_handed(program: &ProgramKind, mesh: &TriangleMesh) -> anyhow::Result<()> {
    anyhow::ensure!(
        mesh.positions.iter().all(|p| p.is_finite()),
        "{} is not handed a mesh with NaN or infinite vertices: no mesh file reader takes one",
        program.name()
    );
    Ok(())
}

impl Kind for Replaying {
    fn label(&self) -> Label<'_> {
        self.program.label()
    }
    fn group(&self) -> Group {
        Group::Program
    }
    fn build(&self, mesh: &TriangleMesh, _: BuildContext) -> anyhow::Result<Box<dyn Backend>> {
        can_be_handed(&self.program, mesh)?;
        let record = lock(&self.record);
        let answered = record
            .answers
            .get(&MeshKey::of(mesh))
            .cloned()
            .unwrap_or_default();
        Ok(Box::new(ReplayingBackend {
            name: self.program.name().to_string(),
            answered,
            unrecorded: Arc::clone(&record.unrecorded),
        }))
    }
}

struct RecordingBackend {
    name: String,
    inner: Box<dyn Backend>,
    asked: SharedAsked,
}

impl RecordingBackend {
    fn ask(&self, ray: &Ray, any_hit: bool) {
        lock(&self.asked).ask(ray, any_hit);
    }
}

impl Intersector for RecordingBackend {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.ask(ray, false);
        self.inner.intersect(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.ask(ray, true);
        self.inner.occluded(ray)
    }
}

impl Backend for RecordingBackend {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn answers(&self) -> Answers {
        self.inner.answers()
    }
    fn build_time(&self) -> Duration {
        Duration::ZERO
    }
    fn bytes(&self) -> Option<usize> {
        None
    }
}

struct ReplayingBackend {
    name: String,
    answered: Arc<Answered>,
    unrecorded: Arc<AtomicU64>,
}

impl ReplayingBackend {
    fn unrecorded(&self) {
        self.unrecorded.fetch_add(1, Ordering::Relaxed);
    }
}

impl Intersector for ReplayingBackend {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match self.answered.closest.get(&ray_bits(ray)) {
            Some(hit) => *hit,
            None => {
                self.unrecorded();
                None
            }
        }
    }
    fn occluded(&self, ray: &Ray) -> bool {
        match self.answered.any_hit.get(&ray_bits(ray)) {
            Some(&occluded) => occluded,
            None => {
                self.unrecorded();
                false
            }
        }
    }
}

impl Backend for ReplayingBackend {
    fn name(&self) -> String {
        self.name.clone()
    }
    /// `t` and the triangle, `u`, `v` when the program gave them; no
    /// normal (the hits file has none).
    fn answers(&self) -> Answers {
        Answers {
            uv: self.answered.gives_uv,
            normal: false,
        }
    }
    fn build_time(&self) -> Duration {
        Duration::ZERO
    }
    fn bytes(&self) -> Option<usize> {
        None
    }
}

/// The answers of a hits file to the rays of its rays file, added to
/// `answered`.
pub fn add_answers(answered: &mut Answered, rays: &[Ray], answers: &[Answer]) {
    for (ray, answer) in rays.iter().zip(answers) {
        match *answer {
            Answer::Closest(hit) => {
                answered.closest.insert(ray_bits(ray), hit);
            }
            Answer::Occluded(occluded) => {
                answered.any_hit.insert(ray_bits(ray), occluded);
            }
        }
    }
}
