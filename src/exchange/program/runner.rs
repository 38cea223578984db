//! Runs a program over the rays it was asked: per mesh, the mesh as PLY
//! and the rays in batches of rays files, the program run on each with a
//! time limit, its hits files read back and checked. A program that cannot
//! start, fails, runs too long or writes a bad file is an error naming it,
//! its command and the last lines it wrote on stderr.

use super::session::{Answered, SharedRecord, add_answers};
use crate::adapters::ProgramCommand;
use crate::backends::ProgramKind;
use crate::check::RaySet;
use crate::exchange::files::{HitsFile, RaysFile};
use crate::geometry::TriangleMesh;
use anyhow::Context;
use std::io::Read;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Lines of a failed program's stderr quoted in its error.
const STDERR_LINES: usize = 12;

/// How often a running program is polled for its end.
const POLL: Duration = Duration::from_millis(5);

/// What running a program over a command's rays took.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Workload {
    pub meshes: usize,
    pub rays: u64,
    pub batches: usize,
    /// Wall time of the program's runs, set-up not counted.
    pub seconds: f64,
}

/// The set written for a batch of closest-hit or any-hit rays.
pub fn batch_set(any_hit: bool) -> RaySet {
    if any_hit {
        RaySet::StabilityCaseAnyHit
    } else {
        RaySet::StabilityCase
    }
}

/// Runs `program` (as `command`) over every mesh and ray `record` holds,
/// adding its answers to the record.
pub fn answer_recorded(
    program: &ProgramKind,
    command: &ProgramCommand,
    record: &SharedRecord,
    progress: &dyn Fn(&str),
) -> anyhow::Result<Workload> {
    let meshes: Vec<_> = {
        let record = record.lock().unwrap_or_else(|p| p.into_inner());
        record
            .meshes
            .iter()
            .map(|(key, mesh, asked)| (*key, mesh.clone(), Arc::clone(asked)))
            .collect()
    };
    let folder = tempfile::tempdir().context("making a folder for a program's files")?;
    let mut workload = Workload {
        meshes: meshes.len(),
        ..Workload::default()
    };
    for (index, (key, mesh, asked)) in meshes.iter().enumerate() {
        let asked = asked.lock().unwrap_or_else(|p| p.into_inner());
        progress(&format!(
            "{}: mesh {} of {}: {} closest-hit and {} any-hit rays",
            program.name(),
            index + 1,
            meshes.len(),
            asked.closest.len(),
            asked.any_hit.len()
        ));
        let mesh_path = folder.path().join(format!("mesh-{index}.ply"));
        write_mesh(&mesh_path, mesh)?;
        let mut answered = Answered {
            gives_uv: true,
            ..Answered::default()
        };
        for (rays, any_hit) in [(&asked.closest, false), (&asked.any_hit, true)] {
            for (batch, chunk) in rays.chunks(program.batch_rays.max(1)).enumerate() {
                let stem = format!(
                    "mesh-{index}-{}-{batch}",
                    if any_hit { "any" } else { "closest" }
                );
                let started = Instant::now();
                let hits = trace_batch(
                    program,
                    command,
                    &mesh_path,
                    &folder.path().join(format!("{stem}.rays")),
                    &folder.path().join(format!("{stem}.hits")),
                    RaysFile {
                        set: batch_set(any_hit),
                        rays: chunk.to_vec(),
                    },
                    mesh.triangle_count(),
                )?;
                workload.seconds += started.elapsed().as_secs_f64();
                workload.batches += 1;
                workload.rays += chunk.len() as u64;
                answered.gives_uv &= any_hit || hits.gives_uv;
                add_answers(&mut answered, chunk, &hits.answers);
            }
        }
        record
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .answers
            .insert(*key, Arc::new(answered));
    }
    Ok(workload)
}

/// The PLY of `mesh` at `path`, every f32 exact.
pub fn write_mesh(path: &Path, mesh: &TriangleMesh) -> anyhow::Result<()> {
    std::fs::write(path, crate::exchange::ply::to_bytes(mesh, &[]))
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes `rays` to `rays_path`, runs the program on it and reads back the
/// hits it wrote to `hits_path`, which must answer every ray of the set.
pub fn trace_batch(
    program: &ProgramKind,
    command: &ProgramCommand,
    mesh_path: &Path,
    rays_path: &Path,
    hits_path: &Path,
    rays: RaysFile,
    triangles: usize,
) -> anyhow::Result<HitsFile> {
    rays.write(rays_path)?;
    run(program, command.with_files(mesh_path, rays_path, hits_path))?;
    let hits = HitsFile::read(hits_path)
        .with_context(|| format!("{} wrote a bad hits file", program.name()))?;
    hits.check_answers(&rays, triangles)
        .with_context(|| format!("{} answered other rays than it was asked", program.name()))?;
    Ok(hits)
}

/// `raycheck trace` with a program: `mesh` written as PLY beside the hits,
/// the program run once on the rays file at `rays_path`, its hits at
/// `hits_path` checked against it.
pub fn trace_file(
    program: &ProgramKind,
    command: &ProgramCommand,
    mesh: &TriangleMesh,
    rays_path: &Path,
    hits_path: &Path,
) -> anyhow::Result<HitsFile> {
    let rays = RaysFile::read(rays_path)?;
    let folder = tempfile::tempdir().context("making a folder for the mesh")?;
    let mesh_path = folder.path().join("mesh.ply");
    write_mesh(&mesh_path, mesh)?;
    run(
        program,
        command.with_files(&mesh_path, rays_path, hits_path),
    )?;
    let hits = HitsFile::read(hits_path)
        .with_context(|| format!("{} wrote a bad hits file", program.name()))?;
    hits.check_answers(&rays, mesh.triangle_count())
        .with_context(|| format!("{} answered other rays than it was asked", program.name()))?;
    Ok(hits)
}

/// Runs `command` for `program` within its time limit. The program gets a
/// process group of its own, so that stopping it also stops whatever it
/// started (a shell's children would otherwise keep its stderr open); on
/// Linux it is also killed when raycheck dies ([`die_with_parent`]), which
/// its own group would otherwise keep it from hearing.
fn run(program: &ProgramKind, mut command: Command) -> anyhow::Result<()> {
    let line = command_line(&command);
    let name = program.name();
    die_with_parent(&mut command);
    let mut child = command
        .process_group(0)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("{name}: cannot start `{line}`"))?;
    let mut stderr = child.stderr.take().expect("stderr is piped");
    let reader = std::thread::spawn(move || {
        let mut bytes = Vec::new();
        let _ = stderr.read_to_end(&mut bytes);
        bytes
    });
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        if started.elapsed() > program.timeout {
            kill_group(child.id());
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(POLL);
    };
    let stderr = last_lines(&reader.join().unwrap_or_default());
    match status {
        Some(status) if status.success() => Ok(()),
        Some(status) => anyhow::bail!("{name}: `{line}` failed ({status}){stderr}"),
        None => anyhow::bail!(
            "{name}: `{line}` ran past its time limit of {} s and was stopped{stderr}",
            program.timeout.as_secs_f64()
        ),
    }
}

/// Makes the program started by `command` receive SIGKILL when the thread
/// that starts it ends, as when raycheck is killed or interrupted: in a
/// group of its own, it would not get the terminal's Ctrl-C, and would
/// run on, orphaned (prctl(2), `PR_SET_PDEATHSIG`). [`run`] waits for the
/// program on that thread, so the thread outlives it otherwise.
#[cfg(target_os = "linux")]
fn die_with_parent(command: &mut Command) {
    // SAFETY: the closure runs in the forked child before exec and makes
    // only async-signal-safe calls (prctl, getppid), touching no memory
    // shared with the parent.
    unsafe {
        let parent = libc::getpid();
        command.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == -1 {
                return Err(std::io::Error::last_os_error());
            }
            // The parent died before the signal was asked for.
            if libc::getppid() != parent {
                return Err(std::io::Error::other("raycheck exited"));
            }
            Ok(())
        });
    }
}

#[cfg(not(target_os = "linux"))]
fn die_with_parent(_command: &mut Command) {}

/// Stops the process group `leader` leads.
fn kill_group(leader: u32) {
    // SAFETY: kill(2) with a negative pid signals the process group; it
    // reads no memory of ours. The group is the child's own (made by
    // `process_group(0)`), still there: the child is not yet waited for.
    unsafe {
        libc::kill(-(leader as libc::pid_t), libc::SIGKILL);
    }
}

/// `command` as one line.
fn command_line(command: &Command) -> String {
    std::iter::once(command.get_program())
        .chain(command.get_args())
        .map(|word| word.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The last lines a program wrote on stderr, as the tail of an error.
fn last_lines(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = text.lines().collect();
    if lines.is_empty() {
        return String::new();
    }
    let tail = &lines[lines.len().saturating_sub(STDERR_LINES)..];
    format!("; its last lines on stderr:\n{}", tail.join("\n"))
}
