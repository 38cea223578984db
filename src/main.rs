//! The `raycheck` command line: a thin layer over the library.
//!
//! Exit status: 0 when the command ran and found nothing wrong, 1 when it
//! ran and found a wrong answer of the backend under check (the first of
//! `--backends`), 2 when it could not run.

use anyhow::Context;
use clap::{Parser, Subcommand, ValueEnum};
use raycheck::backends::{BackendName, DEFAULT_BACKENDS, OurBuilder, embree_device};
use raycheck::bvh::wide::{Kernel, KernelChoice};
use raycheck::check::layered::{LayeredBackend, render_checked, render_debug_view};
use raycheck::exchange::{HitsFile, RaysFile, SetName, case_rays, scene_rays};
use raycheck::parallel::thread_pool;
use raycheck::perf::{PerfOptions, PerfReport};
use raycheck::render::RenderSettings;
use raycheck::render::debug::DebugView;
use raycheck::report::{Form, ReportOptions, write_report};
use raycheck::results::{RunMeta, Verdicts, compare_scene};
use raycheck::scene;
use raycheck::stability;
use raycheck_reference::Isa;
use std::path::{Path, PathBuf};
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

/// The backends a command runs, in order; the first is the one checked.
#[derive(clap::Args)]
struct BackendList {
    /// Comma-separated backends: ours, ours-sah, ours-median,
    /// embree[-low|-medium|-high][-robust]. The first is the one checked.
    #[arg(long, default_value = DEFAULT_BACKENDS)]
    backends: String,
    /// Which of our builders `ours` stands for.
    #[arg(long, value_enum, default_value_t = BuilderArg::Wide)]
    builder: BuilderArg,
    /// The kernel the wide BVH (`ours`) traverses with: auto (the widest
    /// this CPU runs), avx512, avx2 or scalar.
    #[arg(long, default_value_t = KernelChoice::Auto)]
    kernel: KernelChoice,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes with their triangle counts and features.
    Scenes,
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
        #[arg(long)]
        threads: Option<usize>,
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
        #[arg(long)]
        threads: Option<usize>,
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
        /// binary BVH (--backend ours --builder sah|median).
        #[arg(long, value_name = "VIEW")]
        debug: Option<String>,
        /// Output file (.png or .exr).
        #[arg(short, long, required_unless_present = "explain")]
        output: Option<PathBuf>,
    },
    /// Time every backend side by side: builds, primary, shadow and diffuse
    /// rays, memory, and how each grows with the triangle count.
    Perf {
        /// Three small scenes, fewer rays and runs: a fast smoke run.
        #[arg(long)]
        quick: bool,
        /// Measure on this many threads only (default: 1 and all cores).
        #[arg(long)]
        threads: Option<usize>,
        #[command(flatten)]
        backends: BackendList,
        /// Also write every number as JSON: a saved run for --baseline.
        #[arg(long, alias = "save")]
        json: Option<PathBuf>,
        /// Also write the tables as Markdown, headed by where and when they
        /// were measured.
        #[arg(long)]
        markdown: Option<PathBuf>,
        /// Compare every metric with a saved run; exit 1 when any is slower
        /// beyond its noise (the bootstrap interval of the median ratio).
        #[arg(long)]
        baseline: Option<PathBuf>,
        /// The instruction set Embree's kernels may use at most: auto (the
        /// widest it has), avx2 or avx512.
        #[arg(long, default_value_t = Isa::Auto)]
        embree_isa: Isa,
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
        #[arg(long)]
        threads: Option<usize>,
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
    /// tracer (layout: docs/exchange.md).
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
        /// The rays file to write.
        #[arg(long)]
        out: PathBuf,
        /// Also write the mesh as binary PLY (every f32 exact); required for
        /// a stability case, whose meshes no scene name loads.
        #[arg(long)]
        mesh_out: Option<PathBuf>,
    },
    /// Trace a rays file with one backend and write its hits file.
    Trace {
        /// The scene name or mesh (.ply from `rays --mesh-out`) of the rays.
        scene: String,
        rays: PathBuf,
        #[arg(long, default_value = "ours")]
        backend: String,
        #[arg(long)]
        out: PathBuf,
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Judge a hits file exactly, beside Embree (MEDIUM, ROBUST). Exits 1
    /// when any of its answers is wrong.
    Judge {
        /// The scene name or mesh (.ply from `rays --mesh-out`) of the rays.
        scene: String,
        rays: PathBuf,
        hits: PathBuf,
        #[arg(long)]
        threads: Option<usize>,
        /// Also write the summary, with replayable rays, as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Error against run time: sampling error of every sampled scene
    /// against samples and time, what each BVH choice costs and when it
    /// pays off, and what robustness costs (docs/sweep.md).
    Sweep(SweepArgs),
    /// Write the report: performance, renders and agreement for every scene.
    Report {
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Three small scenes, small images, every section's quick form: a
        /// smoke run.
        #[arg(long, conflicts_with = "full")]
        quick: bool,
        /// Every section in its full form (the full stability catalogue too).
        #[arg(long)]
        full: bool,
        #[arg(long)]
        threads: Option<usize>,
        /// A folder of runs saved with `raycheck perf --json`, plotted as the
        /// performance history.
        #[arg(long, default_value = "perf-history")]
        history: PathBuf,
    },
}

#[derive(clap::Args)]
struct SweepArgs {
    /// Only these scenes (names or paths), in every part they apply to.
    scenes: Vec<String>,
    /// Smaller images, fewer counts, choices and scenes: under a minute.
    #[arg(long)]
    quick: bool,
    /// Worker threads (default: every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Also write every number as JSON (keys: docs/sweep.md).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Also write the plots and tables as a page (index.html, sweep.md, SVG).
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum BuilderArg {
    Wide,
    Sah,
    Median,
}

impl BackendList {
    /// The parsed list, with `ours` standing for the chosen builder.
    fn names(&self) -> anyhow::Result<Vec<BackendName>> {
        BackendName::parse_list(&self.backends)?
            .into_iter()
            .map(|name| self.resolve(name))
            .collect()
    }

    /// `name`, with `ours` standing for the chosen builder and kernel;
    /// an error when this CPU cannot run the kernel.
    fn resolve(&self, name: BackendName) -> anyhow::Result<BackendName> {
        let builder = match (self.builder, self.kernel) {
            (BuilderArg::Wide, KernelChoice::Auto) => OurBuilder::Wide,
            (BuilderArg::Wide, choice) => OurBuilder::WideKernel(Kernel::resolve(choice)?),
            (BuilderArg::Sah, _) => OurBuilder::Sah,
            (BuilderArg::Median, _) => OurBuilder::Median,
        };
        Ok(match name {
            BackendName::Ours(OurBuilder::Wide) => BackendName::Ours(builder),
            other => other,
        })
    }
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

/// Exit 1 when `faults` is not zero.
fn finding(faults: u64) -> ExitCode {
    if faults == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// The first backend's wrong answers, distances off and non-finite outputs.
fn faults_of_first(verdicts: &Verdicts) -> u64 {
    verdicts
        .backends
        .first()
        .map_or(0, |b| b.faults() + b.nan_outputs)
}

fn write_json(path: Option<&Path>, value: &impl serde::Serialize) -> anyhow::Result<()> {
    if let Some(path) = path {
        std::fs::write(path, serde_json::to_string_pretty(value)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Scenes => {
            print!("{}", raycheck::results::scene_catalogue()?.to_text());
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare {
            scene,
            backends,
            res,
            threads,
            json,
        } => {
            let names = backends.names()?;
            let scene = scene::load(&scene)?;
            let pool = thread_pool(threads)?;
            let meta = RunMeta::collect(pool.current_num_threads());
            let device = embree_device(pool.current_num_threads())?;
            let summary = pool.install(|| compare_scene(&scene, &names, &device, res))?;
            print!("{}", summary.table(&meta.caption()).to_text());
            write_json(json.as_deref(), &summary)?;
            Ok(finding(faults_of_first(&summary.verdicts)))
        }
        Command::Render {
            scene,
            backend,
            backends,
            res,
            threads,
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
                ..parse_resolution(&res)?
            };
            let output = output.context("an output file (-o) is required")?;
            let pool = thread_pool(threads)?;
            let meta = RunMeta::collect(pool.current_num_threads());
            let device = embree_device(pool.current_num_threads())?;
            let names = backends.names()?;
            let code = if backend == "checked" {
                let layered = names
                    .iter()
                    .map(|&name| LayeredBackend::build(name, &scene, &device))
                    .collect::<anyhow::Result<Vec<_>>>()?;
                let run = pool.install(|| render_checked(&scene, &layered, &settings));
                let verdicts = Verdicts::judge_layers(&scene, &run.logs);
                print!("{}", verdicts_table(&verdicts, &meta).to_text());
                run.image.save(&output)?;
                finding(faults_of_first(&verdicts))
            } else {
                let name = backends.resolve(backend.parse()?)?;
                match debug {
                    Some(view) => {
                        let view: DebugView = view.parse()?;
                        let debug = pool.install(|| {
                            render_debug_view(name, &scene, &device, view, &settings)
                        })?;
                        println!("{view}: {}", debug.legend);
                        debug.image.save(&output)?;
                    }
                    None => {
                        let layered = LayeredBackend::build(name, &scene, &device)?;
                        pool.install(|| layered.render(&scene, &settings))
                            .save(&output)?
                    }
                }
                ExitCode::SUCCESS
            };
            println!("wrote {}", output.display());
            Ok(code)
        }
        Command::Perf {
            quick,
            threads,
            backends,
            json,
            markdown,
            baseline,
            embree_isa,
        } => {
            let options = PerfOptions {
                quick,
                threads,
                backends: backends.names()?,
                embree_isa,
            };
            let saved = baseline.as_deref().map(PerfReport::load).transpose()?;
            let report = raycheck::perf::run(&options, &|step| eprintln!("{step}"))?;
            print!("{}", report.text());
            write_json(json.as_deref(), &report)?;
            if let Some(path) = markdown {
                std::fs::write(&path, report.markdown_page())
                    .with_context(|| format!("writing {}", path.display()))?;
            }
            let Some(saved) = saved else {
                return Ok(ExitCode::SUCCESS);
            };
            let changes = raycheck::perf::baseline::compare(&saved, &report);
            print!(
                "\n{}",
                raycheck::perf::baseline::table(&changes, &saved, &report).to_text()
            );
            let slower = changes
                .iter()
                .filter(|c| c.verdict == raycheck::perf::baseline::Verdict::Slower)
                .count();
            Ok(finding(slower as u64))
        }
        Command::Stability {
            quick,
            case,
            threads,
            backends,
            json,
            markdown,
        } => {
            let names = backends.names()?;
            let pool = thread_pool(threads)?;
            let meta = RunMeta::collect(pool.current_num_threads());
            let device = embree_device(pool.current_num_threads())?;
            let context = stability::Context {
                backends: &names,
                device: &device,
                quick,
                recorder: None,
            };
            let results = pool.install(|| stability::run_catalogue(&context, case.as_deref()));
            print!("{}", stability::table::to_text(&results, &meta.caption()));
            write_json(json.as_deref(), &results)?;
            if let Some(path) = markdown {
                let page =
                    stability::table::markdown_page(&results, &meta, quick, &backends.backends);
                std::fs::write(&path, page)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
            let faults: u64 = results
                .iter()
                .map(|r| r.panics + faults_of_first(&r.verdicts))
                .sum();
            Ok(finding(faults))
        }
        Command::Rays {
            scene,
            set,
            res,
            full,
            out,
            mesh_out,
        } => {
            let exported = match (set.parse::<SetName>()?, scene) {
                (SetName::Scene(set), Some(scene)) => scene_rays(&scene::load(&scene)?, set, res)?,
                (SetName::Scene(set), None) => {
                    anyhow::bail!("the {} set needs a scene", set.name())
                }
                (SetName::Case(case), None) => {
                    anyhow::ensure!(
                        mesh_out.is_some(),
                        "a stability case's rays need --mesh-out: no scene name loads its meshes"
                    );
                    let pool = thread_pool(None)?;
                    let device = embree_device(pool.current_num_threads())?;
                    pool.install(|| case_rays(case, &device, full))?
                }
                (SetName::Case(case), Some(_)) => {
                    anyhow::bail!("stability case {case} brings its own meshes: give no scene")
                }
            };
            RaysFile {
                set: exported.set,
                rays: exported.rays,
            }
            .write(&out)?;
            println!("wrote {} ({})", out.display(), exported.note);
            if let Some(path) = mesh_out {
                anyhow::ensure!(
                    path.extension().is_some_and(|e| e == "ply"),
                    "{}: the mesh is written as PLY; name it .ply",
                    path.display()
                );
                let bytes = raycheck::exchange::ply::to_bytes(&exported.mesh, &[exported.note]);
                std::fs::write(&path, bytes)
                    .with_context(|| format!("writing {}", path.display()))?;
                println!("wrote {}", path.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Trace {
            scene,
            rays,
            backend,
            out,
            threads,
        } => {
            let scene = scene::load(&scene)?;
            let rays = RaysFile::read(&rays)?;
            let pool = thread_pool(threads)?;
            let device = embree_device(pool.current_num_threads())?;
            let backend = backend
                .parse::<BackendName>()?
                .build(&scene.mesh, &device)?;
            pool.install(|| raycheck::exchange::trace(backend.as_ref(), &rays))
                .write(&out)?;
            println!("wrote {}", out.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Judge {
            scene,
            rays,
            hits,
            threads,
            json,
        } => {
            let scene = scene::load(&scene)?;
            let rays_file = RaysFile::read(&rays)?;
            let hits_file = HitsFile::read(&hits)?;
            let pool = thread_pool(threads)?;
            let meta = RunMeta::collect(pool.current_num_threads());
            let device = embree_device(pool.current_num_threads())?;
            let name = hits
                .file_name()
                .map_or("hits".into(), |n| n.to_string_lossy());
            let summary = pool.install(|| {
                raycheck::exchange::judge(&scene, &rays_file, &hits_file, &name, &device)
            })?;
            print!("{}", summary.table(&meta.caption()).to_text());
            write_json(json.as_deref(), &summary)?;
            Ok(finding(faults_of_first(&summary.verdicts)))
        }
        Command::Sweep(args) => {
            let options = raycheck::sweep::SweepOptions {
                scenes: args.scenes,
                quick: args.quick,
                threads: args.threads,
            };
            let sweep = raycheck::sweep::run(&options, &|step| eprintln!("{step}"))?;
            for table in sweep.tables() {
                println!("{}", table.to_text());
            }
            write_json(args.json.as_deref(), &sweep)?;
            if let Some(out) = args.out {
                let index = raycheck::report::sweep::write_page(&out, &sweep)?;
                println!("wrote {}", index.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Report {
            out,
            quick,
            full,
            threads,
            history,
        } => {
            let form = match (quick, full) {
                (true, _) => Form::Quick,
                (_, true) => Form::Full,
                _ => Form::Standard,
            };
            let index = write_report(&ReportOptions {
                out,
                form,
                threads,
                history: Some(history),
            })?;
            println!("wrote {}", index.display());
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// A checked render's verdicts as a table, a row per backend.
fn verdicts_table(verdicts: &Verdicts, meta: &RunMeta) -> raycheck::results::Table {
    raycheck::results::tally::table(
        &format!(
            "checked render: {} queries, {} judged, {} ambiguous",
            verdicts.rays, verdicts.judged, verdicts.ambiguous
        ),
        verdicts,
        &meta.caption(),
    )
}

fn parse_resolution(text: &str) -> anyhow::Result<RenderSettings> {
    let parse = |s: &str| {
        s.parse::<u32>()
            .ok()
            .filter(|&v| (1..=16384).contains(&v))
            .with_context(|| format!("bad resolution '{text}': expected N or WxH, 1 to 16384"))
    };
    let (width, height) = match text.split_once(['x', 'X']) {
        Some((w, h)) => (parse(w)?, parse(h)?),
        None => (parse(text)?, parse(text)?),
    };
    Ok(RenderSettings {
        width,
        height,
        ..RenderSettings::square(width)
    })
}
