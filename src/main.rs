//! The `raycheck` command line: parses the arguments, makes the run once
//! ([`RunContext`]) and hands it to the library's entry point of each
//! command.
//!
//! Exit status: 0 when the command ran and found nothing wrong, 1 when it
//! ran and found a wrong answer of the backend under check (the first of
//! `--backends`), 2 when it could not run.

use anyhow::Context;
use clap::{Parser, Subcommand};
use raycheck::backends::{BackendName, DEFAULT_BACKENDS, Registry};
use raycheck::bvh::wide::{Kernel, KernelChoice};
use raycheck::exchange::ExportRequest;
use raycheck::exchange::program::{WithPrograms, with_programs};
use raycheck::parallel::InstructionSets;
use raycheck::perf::{PerfOptions, PerfReport};
use raycheck::render::RenderSettings;
use raycheck::report::ReportOptions;
use raycheck::results::rendered::{Drawing, draw, verdicts_table};
use raycheck::results::{write_json, write_text};
use raycheck::run::{Form, RunContext, RunOptions};
use raycheck::{exchange, perf, results, scene, stability, sweep};
use raycheck_reference::Isa;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "raycheck",
    version,
    about = "A BVH ray tracer checked hit by hit against Embree 4"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The run's shared arguments.
#[derive(clap::Args)]
struct RunArgs {
    /// Worker threads, for our tracer and Embree's builds alike (default:
    /// every core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// The kernel our wide BVH (`ours`) traverses with: auto (the widest
    /// this CPU runs well), avx512-zmm (AVX-512 pairing leaves in 512-bit
    /// registers), avx512, avx2 or scalar; every kernel gives the same
    /// answers.
    #[arg(long, default_value_t = KernelChoice::Auto)]
    kernel: KernelChoice,
    /// The widest instruction set Embree's kernels may use: auto (the
    /// widest it has), avx2 or avx512.
    #[arg(long, default_value_t = Isa::Auto)]
    embree_isa: Isa,
}

impl RunArgs {
    fn start(&self, form: Form) -> anyhow::Result<RunContext> {
        RunContext::new(RunOptions {
            threads: self.threads.map(|n| n as usize),
            form,
            sets: InstructionSets {
                kernel: Kernel::resolve(self.kernel)?,
                embree: self.embree_isa,
            },
        })
    }
}

/// The backends a command runs, in order; the first is the one checked.
#[derive(clap::Args)]
struct BackendList {
    #[arg(long, default_value = DEFAULT_BACKENDS, help = BackendName::help())]
    backends: String,
    #[command(flatten)]
    tracers: TracersArg,
}

impl BackendList {
    fn names(&self) -> anyhow::Result<Vec<BackendName>> {
        Ok(self.tracers.registry()?.parse_list(&self.backends)?)
    }
}

/// Programs of one's own, as backends.
#[derive(clap::Args)]
struct TracersArg {
    /// A tracers file naming programs as backends: [tracer.NAME] tables
    /// with command = [PROGRAM, ARGS...], run as PROGRAM ARGS... MESH.ply
    /// RAYS HITS (docs/exchange.md).
    #[arg(long, value_name = "FILE")]
    tracers: Option<PathBuf>,
}

impl TracersArg {
    fn registry(&self) -> anyhow::Result<Registry> {
        Registry::with_tracers(self.tracers.as_deref())
    }
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes with their triangle counts and features.
    Scenes,
    /// List every backend `--backends` takes, by group.
    Backends {
        #[command(flatten)]
        tracers: TracersArg,
    },
    /// Trace a scene's primary, shadow and reflection rays through every
    /// backend; judge every disagreement and 1% of the agreements exactly.
    /// Exits 1 when any answer of the first backend is wrong.
    Compare {
        /// A scene name (see `raycheck scenes`) or a .toml/.obj/.ply/.glb path.
        scene: String,
        #[command(flatten)]
        backends: BackendList,
        /// Primary rays per side of the view.
        #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
        res: u32,
        #[command(flatten)]
        run: RunArgs,
        /// Also write the summary, with replayable rays, as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Render a scene to a PNG or EXR.
    Render {
        scene: String,
        /// A backend name (see --backends), or `checked` to ask every
        /// backend of --backends at once and render the first one's answers.
        #[arg(long, default_value = "ours")]
        backend: String,
        #[command(flatten)]
        backends: BackendList,
        /// Image size: N (square) or WxH.
        #[arg(long, default_value = "800")]
        res: String,
        #[command(flatten)]
        run: RunArgs,
        /// Camera samples per pixel (default: the scene's own).
        #[arg(long)]
        spp: Option<u32>,
        /// Seed of the render's random numbers.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Print the passes the render will run, and stop.
        #[arg(long)]
        explain: bool,
        /// Draw a debug view instead: bvh-level=N (the boxes of BVH level N,
        /// root 0, over the render), heat (BVH nodes visited per pixel),
        /// normals, barycentrics, texcoords, bloom-mask, or rays=X,Y (every
        /// ray of pixel X,Y over the render). bvh-level and heat read our
        /// trees (--backend ours, ours-sah or ours-median).
        #[arg(long, value_name = "VIEW")]
        debug: Option<String>,
        /// Output file (.png or .exr).
        #[arg(short, long, required_unless_present = "explain")]
        output: Option<PathBuf>,
    },
    /// Time every backend side by side: builds, primary, shadow and diffuse
    /// rays, memory, and how each grows with the triangle count; on one
    /// thread and every core, or on --threads only.
    Perf {
        /// Three small scenes, fewer rays and runs: a fast smoke run.
        #[arg(long)]
        quick: bool,
        #[command(flatten)]
        run: RunArgs,
        #[command(flatten)]
        backends: BackendList,
        /// Only these built-in scenes, comma-separated, in this order
        /// (default: the benchmark scenes, and dragon-14m unless --quick).
        #[arg(long, value_delimiter = ',', value_name = "LIST")]
        scenes: Vec<String>,
        /// Also write every number as JSON: a saved run for --baseline.
        #[arg(long, alias = "save")]
        json: Option<PathBuf>,
        /// Also write the tables as Markdown, headed by where and when they
        /// were measured.
        #[arg(long)]
        markdown: Option<PathBuf>,
        /// Compare every metric with a saved run; exit 1 when any is slower
        /// beyond its noise (Welch's t-test on the runs' logs, Holm's
        /// procedure over all metrics at 5% together).
        #[arg(long)]
        baseline: Option<PathBuf>,
    },
    /// Run the numerical-stability catalogue: stiff and extreme cases through
    /// every backend, judged exactly. Exits 1 when the first backend gives a
    /// wrong answer or a non-finite output, or a case panics.
    Stability {
        /// Few rays per case: a fast run for CI.
        #[arg(long)]
        quick: bool,
        /// Only the cases whose name contains this text.
        #[arg(long)]
        case: Option<String>,
        #[command(flatten)]
        run: RunArgs,
        #[command(flatten)]
        backends: BackendList,
        /// Also write one JSON object per case.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Also write the tables as Markdown, headed by where and when they
        /// were measured.
        #[arg(long)]
        markdown: Option<PathBuf>,
    },
    /// Write a ray set, and the exact mesh it was made for, for another
    /// tracer; or a stability case as a bundle: a folder of (mesh, rays)
    /// pairs, as the case judges them (layout: docs/exchange.md).
    Rays {
        /// A scene name or mesh path; none for a stability case.
        scene: Option<String>,
        /// primary, shadow, reflection, diffuse, or a stability case's name.
        #[arg(long)]
        set: String,
        /// Primary rays per side of the view (scene sets).
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=16384))]
        res: u32,
        /// A stability case's full form instead of its quick one.
        #[arg(long)]
        full: bool,
        #[command(flatten)]
        run: RunArgs,
        /// The rays file to write; for a stability case, the bundle's folder.
        #[arg(long)]
        out: PathBuf,
        /// Also write the mesh as binary PLY (every f32 exact). For a
        /// stability case: write instead every mesh merged into this one
        /// PLY and every closest-hit ray into --out, traced against all of
        /// it (another problem than the case's, kept as a scene of its own).
        #[arg(long)]
        mesh_out: Option<PathBuf>,
    },
    /// Trace a rays file with one backend and write its hits file; or every
    /// rays file of a bundle, into a folder of hits files.
    Trace {
        /// SCENE RAYS (a scene name or mesh, .ply from `rays --mesh-out`, and
        /// a rays file), or BUNDLE (a folder from `rays --set CASE`).
        #[arg(required = true, num_args = 1..=2, value_name = "SCENE RAYS | BUNDLE")]
        inputs: Vec<String>,
        #[arg(long, default_value = "ours")]
        backend: String,
        #[command(flatten)]
        tracers: TracersArg,
        /// The hits file to write; for a bundle, the folder of hits files.
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        run: RunArgs,
    },
    /// Judge a hits file (or a bundle's folder of hits files) exactly,
    /// beside built-in backends. Exits 1 when any of its answers is wrong.
    Judge {
        /// SCENE RAYS HITS (a scene name or mesh, .ply from `rays
        /// --mesh-out`, a rays file, a hits file), or BUNDLE HITS (a folder
        /// from `rays --set CASE`, a folder of hits files from `trace`).
        #[arg(required = true, num_args = 2..=3, value_name = "SCENE RAYS HITS | BUNDLE HITS")]
        inputs: Vec<String>,
        /// The backends judged beside the hits, as in `compare` and
        /// `stability`: built-in ones (a program is judged through its own
        /// hits).
        #[arg(long, default_value = DEFAULT_BACKENDS, help = BackendName::help())]
        backends: String,
        #[command(flatten)]
        run: RunArgs,
        /// Also write the summary as JSON (with replayable rays for a hits
        /// file, with each pair's verdicts for a bundle).
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Set up a program backend (for the tracers in `adapters/`, its Python
    /// environment with pinned packages or the compiled C++ template, in
    /// the cache; nothing when already there) and print the command that
    /// runs it: append MESH.ply RAYS HITS.
    Adapter {
        /// mitsuba-scalar, mitsuba-llvm, trimesh, cpp-template, or a program
        /// of the tracers file.
        name: String,
        #[command(flatten)]
        tracers: TracersArg,
    },
    /// Error against run time: sampling error of every sampled scene
    /// against samples and time, what each BVH choice costs and when it
    /// pays off, and what robustness costs (docs/sweep.md).
    Sweep {
        /// Only these scenes (names or paths), in every part they apply to.
        scenes: Vec<String>,
        /// Smaller images, fewer counts, choices and scenes: under a minute.
        #[arg(long)]
        quick: bool,
        #[command(flatten)]
        run: RunArgs,
        /// Also write every number as JSON (keys: docs/sweep.md).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Also write the plots and tables as a page (index.html, sweep.md, SVG).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Write the report: performance, renders and agreement for every scene.
    Report {
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Three small scenes, small images, every section's quick form: a
        /// smoke run.
        #[arg(long, conflicts_with = "full")]
        quick: bool,
        /// Every section in its full form: the full stability catalogue and
        /// sweep, and the 13.9M-triangle dragon.
        #[arg(long)]
        full: bool,
        #[command(flatten)]
        run: RunArgs,
        /// A folder of runs saved with `raycheck perf --json`, plotted as the
        /// performance history.
        #[arg(long, default_value = "perf-history")]
        history: PathBuf,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::from(2)
        }
    }
}

/// Exit 1 when a command found `faults` (wrong answers of the checked
/// backend, panics, regressions).
fn finding(faults: u64) -> ExitCode {
    if faults == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn progress(step: &str) {
    eprintln!("{step}");
}

/// Exit 1 when a command found `faults`; else 2 when a program among its
/// backends failed (its error printed, the rest of the results kept);
/// else 0.
fn outcome<T>(faults: u64, programs: &WithPrograms<T>, run: &RunContext) -> ExitCode {
    if !programs.programs.is_empty() {
        let caption = run.meta().caption();
        print!(
            "{}",
            exchange::program::table(&programs.programs, &caption).to_text()
        );
    }
    for failed in programs.failures() {
        eprintln!(
            "error: {} was left out: {}",
            failed.name,
            failed.error.as_deref().unwrap_or_default()
        );
    }
    if faults > 0 {
        ExitCode::FAILURE
    } else if programs.failures().is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(2)
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Scenes => print!("{}", results::scene_catalogue()?.to_text()),
        Command::Backends { tracers } => {
            print!(
                "{}",
                results::backend_catalogue(&tracers.registry()?).to_text()
            )
        }
        Command::Compare {
            scene,
            backends,
            res,
            run,
            json,
        } => {
            let names = backends.names()?;
            let scene = scene::load(&scene)?;
            let run = run.start(Form::Full)?;
            let compared = with_programs(
                &names,
                |names| results::compare_scene(&scene, names, run.workers(), res),
                &progress,
            )?;
            let summary = &compared.value;
            print!("{}", summary.table(&run.meta().caption()).to_text());
            json.map(|path| write_json(&path, summary)).transpose()?;
            return Ok(outcome(summary.verdicts.faults_of_first(), &compared, &run));
        }
        Command::Render {
            scene,
            backend,
            backends,
            res,
            run,
            spp,
            seed,
            explain,
            debug,
            output,
        } => {
            let scene = scene::load(&scene)?;
            if explain {
                print!("{}", raycheck::render::pipeline::explain(&scene, spp));
                return Ok(ExitCode::SUCCESS);
            }
            let settings = RenderSettings {
                samples_per_pixel: spp,
                seed,
                ..RenderSettings::of_size(&res)?
            };
            let output = output.context("an output file (-o) is required")?;
            let drawing = match (backend.as_str(), debug) {
                ("checked", _) => Drawing::Checked(backends.names()?),
                (name, None) => Drawing::Render(name.parse()?),
                (name, Some(view)) => Drawing::Debug(name.parse()?, view.parse()?),
            };
            let run = run.start(Form::Full)?;
            let drawn = draw(&scene, &drawing, run.workers(), &settings)?;
            drawn.legend.iter().for_each(|legend| println!("{legend}"));
            if let Some(verdicts) = &drawn.verdicts {
                print!("{}", verdicts_table(verdicts, run.meta()).to_text());
            }
            drawn.image.save(&output)?;
            println!("wrote {}", output.display());
            return Ok(finding(drawn.verdicts.map_or(0, |v| v.faults_of_first())));
        }
        Command::Perf {
            quick,
            run,
            backends,
            scenes,
            json,
            markdown,
            baseline,
        } => {
            let saved = baseline.as_deref().map(PerfReport::load).transpose()?;
            let run = run.start(Form::from_flags(quick, false, Form::Full))?;
            let options = PerfOptions::of_run(&run, backends.names()?).only(scenes)?;
            let report = perf::run(&run, &options, &progress)?;
            print!("{}", report.text());
            json.map(|path| write_json(&path, &report)).transpose()?;
            markdown
                .map(|path| write_text(&path, &report.markdown_page()))
                .transpose()?;
            if let Some(saved) = saved {
                let changes = perf::baseline::compare(&saved, &report);
                print!(
                    "\n{}",
                    perf::baseline::table(&changes, &saved, &report).to_text()
                );
                return Ok(finding(perf::baseline::slower(&changes) as u64));
            }
        }
        Command::Stability {
            quick,
            case,
            run,
            backends,
            json,
            markdown,
        } => {
            let names = backends.names()?;
            let run = run.start(Form::from_flags(quick, false, Form::Full))?;
            let judged = with_programs(
                &names,
                |names| Ok(stability::run(&run, names, case.as_deref())),
                &progress,
            )?;
            let results = &judged.value;
            print!(
                "{}",
                stability::table::to_text(results, &run.meta().caption())
            );
            json.map(|path| write_json(&path, results)).transpose()?;
            if let Some(path) = markdown {
                let page =
                    stability::table::markdown_page(results, run.meta(), quick, &backends.backends);
                write_text(&path, &page)?;
            }
            return Ok(outcome(stability::faults(results), &judged, &run));
        }
        Command::Rays {
            scene,
            set,
            res,
            full,
            run,
            out,
            mesh_out,
        } => {
            let run = run.start(Form::from_flags(false, full, Form::Quick))?;
            let request = ExportRequest {
                scene: scene.as_deref(),
                set: &set,
                resolution: res,
                out: &out,
                mesh_out: mesh_out.as_deref(),
            };
            for line in exchange::export(&run, &request)? {
                println!("{line}");
            }
        }
        Command::Trace {
            inputs,
            backend,
            tracers,
            out,
            run,
        } => {
            let backend = tracers.registry()?.parse(&backend)?;
            let run = run.start(Form::Full)?;
            println!("{}", exchange::trace_files(&run, &inputs, &backend, &out)?);
        }
        Command::Judge {
            inputs,
            backends,
            run,
            json,
        } => {
            let beside = Registry::built_in().parse_list(&backends)?;
            let run = run.start(Form::Full)?;
            let judged = exchange::judge_files(&run, &inputs, &beside)?;
            print!("{}", judged.table(&run.meta().caption()).to_text());
            json.map(|path| write_json(&path, &judged)).transpose()?;
            let undecided = judged
                .verdicts()
                .backends
                .first()
                .map_or(0, |b| b.undecided);
            if undecided > 0 {
                eprintln!(
                    "note: the referee left {undecided} rays of the hits undecided: \
                     neither found wrong nor admissible within its search budget"
                );
            }
            return Ok(finding(judged.verdicts().faults_of_first()));
        }
        Command::Adapter { name, tracers } => {
            let backend = tracers.registry()?.parse(&name)?;
            let program = backend
                .program()
                .with_context(|| format!("{name} is not a program: it runs in process"))?;
            println!("{}", exchange::program::prepare(program)?);
        }
        Command::Sweep {
            scenes,
            quick,
            run,
            json,
            out,
        } => {
            let run = run.start(Form::from_flags(quick, false, Form::Full))?;
            let options = sweep::SweepOptions { scenes, quick };
            let sweep = sweep::run(&run, &options, &progress)?;
            for table in sweep.tables() {
                println!("{}", table.to_text());
            }
            json.map(|path| write_json(&path, &sweep)).transpose()?;
            if let Some(out) = out {
                let index = raycheck::report::sweep::write_page(&out, &sweep)?;
                println!("wrote {}", index.display());
            }
        }
        Command::Report {
            out,
            quick,
            full,
            run,
            history,
        } => {
            let run = run.start(Form::from_flags(quick, full, Form::Standard))?;
            let options = ReportOptions {
                out,
                history: Some(history),
            };
            let index = raycheck::report::write_report(&run, &options)?;
            println!("wrote {}", index.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}
