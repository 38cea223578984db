//! The `raycheck` command line: a thin layer over the library.

use anyhow::Context;
use clap::{Parser, Subcommand, ValueEnum};
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::check::{self, CheckLog, CompareSummary, layered};
use raycheck::parallel::thread_pool;
use raycheck::perf::PerfOptions;
use raycheck::render::debug::{DebugView, render_debug};
use raycheck::render::pipeline::Passes;
use raycheck::render::{RenderSettings, render_layers};
use raycheck::report::measure::REFERENCE_OPTIONS;
use raycheck::report::{ReportOptions, write_report};
use raycheck::scene::{self, Scene};
use raycheck::stability;
use raycheck_reference::{BuildQuality, Device, DeviceConfig, SceneOptions};
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

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes with their triangle counts and features.
    Scenes,
    /// Trace a scene's primary, shadow and reflection rays through our BVH
    /// and Embree; judge every difference. Fails when any of ours is wrong.
    Compare {
        /// A scene name (see `raycheck scenes`) or a .toml/.obj/.ply/.glb path.
        scene: String,
        #[arg(long, value_enum, default_value_t = BuilderArg::Sah)]
        builder: BuilderArg,
        #[arg(long, value_enum, default_value_t = QualityArg::Medium)]
        embree_quality: QualityArg,
        /// Use Embree without RTC_SCENE_FLAG_ROBUST.
        #[arg(long)]
        no_robust: bool,
        /// Primary rays per side of the view.
        #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
        res: u32,
        #[arg(long)]
        threads: Option<usize>,
        /// Also write the summary, with replayable disagreeing rays, as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Render a scene to a PNG or EXR.
    Render {
        scene: String,
        #[arg(long, value_enum, default_value_t = BackendArg::Ours)]
        backend: BackendArg,
        #[arg(long, value_enum, default_value_t = BuilderArg::Sah)]
        builder: BuilderArg,
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
        /// ray of pixel X,Y over the render). bvh-level and heat need
        /// --backend ours; the others also run on embree.
        #[arg(long, value_name = "VIEW")]
        debug: Option<String>,
        /// Output file (.png or .exr).
        #[arg(short, long, required_unless_present = "explain")]
        output: Option<PathBuf>,
    },
    /// Time our fast BVH and Embree side by side: builds, primary, shadow and
    /// diffuse rays, memory, and how each grows with the triangle count.
    Perf {
        /// Three small scenes, fewer rays and runs: a fast smoke run.
        #[arg(long)]
        quick: bool,
        /// Measure on this many threads only (default: 1 and all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Also write every number as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Run the numerical-stability catalogue: stiff and extreme cases through
    /// our BVH, Embree default and Embree robust, judged exactly.
    Stability {
        /// Few rays per case: a fast run for CI.
        #[arg(long)]
        quick: bool,
        /// Only the cases whose name contains this text.
        #[arg(long)]
        case: Option<String>,
        #[arg(long)]
        threads: Option<usize>,
        /// Also write one JSON object per case.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// Write the report: performance, renders and agreement for every scene.
    Report {
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Fewer scenes, smaller images: a fast smoke run.
        #[arg(long)]
        quick: bool,
        #[arg(long)]
        threads: Option<usize>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum BuilderArg {
    Median,
    Sah,
}

#[derive(Clone, Copy, ValueEnum)]
enum QualityArg {
    Low,
    Medium,
    High,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum BackendArg {
    Ours,
    Embree,
    Checked,
}

impl BuilderArg {
    fn options(self) -> BuildOptions {
        match self {
            BuilderArg::Median => BuildOptions::median(),
            BuilderArg::Sah => BuildOptions::sah(),
        }
    }
}

impl QualityArg {
    fn quality(self) -> BuildQuality {
        match self {
            QualityArg::Low => BuildQuality::Low,
            QualityArg::Medium => BuildQuality::Medium,
            QualityArg::High => BuildQuality::High,
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Scenes => list_scenes(),
        Command::Compare {
            scene,
            builder,
            embree_quality,
            no_robust,
            res,
            threads,
            json,
        } => {
            let options = SceneOptions {
                quality: embree_quality.quality(),
                robust: !no_robust,
            };
            let summary = run_compare(&scene, builder, options, res, threads)?;
            print_summary(&summary);
            if let Some(path) = json {
                std::fs::write(&path, serde_json::to_string_pretty(&summary)?)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
            let wrong = summary.ours_wrong + summary.ours_t_off;
            anyhow::ensure!(wrong == 0, "the referee found {wrong} of our answers wrong");
            Ok(())
        }
        Command::Render {
            scene,
            backend,
            builder,
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
                println!("{}: {}", scene.name, Passes::for_render(&scene, spp));
                return Ok(());
            }
            let settings = RenderSettings {
                samples_per_pixel: spp,
                seed,
                ..parse_resolution(&res)?
            };
            let output = output.context("an output file (-o) is required")?;
            match debug {
                Some(view) => {
                    let view: DebugView = view.parse()?;
                    run_debug(&scene, backend, builder, view, settings, threads, &output)
                }
                None => run_render(&scene, backend, builder, settings, threads, &output),
            }
        }
        Command::Perf {
            quick,
            threads,
            json,
        } => {
            let report =
                raycheck::perf::run(&PerfOptions { quick, threads }, &|step| eprintln!("{step}"))?;
            println!("{}", report.markdown());
            if let Some(path) = json {
                std::fs::write(&path, serde_json::to_string_pretty(&report)?)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
            Ok(())
        }
        Command::Stability {
            quick,
            case,
            threads,
            json,
        } => run_stability(quick, case.as_deref(), threads, json),
        Command::Report {
            out,
            quick,
            threads,
        } => {
            let index = write_report(&ReportOptions {
                out,
                quick,
                threads,
            })?;
            println!("wrote {}", index.display());
            Ok(())
        }
    }
}

fn list_scenes() -> anyhow::Result<()> {
    println!("{:<14} {:>10}  features", "scene", "triangles");
    for name in scene::builtin_names()? {
        let scene = scene::load(&name)?;
        let features: Vec<String> = scene.features.iter().map(|f| f.to_string()).collect();
        println!(
            "{:<14} {:>10}  {}",
            name,
            scene.mesh.triangle_count(),
            features.join(", ")
        );
    }
    Ok(())
}

fn embree_device(threads: usize) -> anyhow::Result<Device> {
    Ok(Device::new(&DeviceConfig {
        threads: Some(threads),
        verbose: 0,
    })?)
}

fn run_compare(
    scene: &str,
    builder: BuilderArg,
    options: SceneOptions,
    res: u32,
    threads: Option<usize>,
) -> anyhow::Result<CompareSummary> {
    let scene = scene::load(scene)?;
    let pool = thread_pool(threads)?;
    let device = embree_device(pool.current_num_threads())?;
    let reference = raycheck::backends::embree::build_scene(&device, &scene.mesh, options)?;
    let bvh = Bvh::build(&scene.mesh, &builder.options());
    Ok(pool.install(|| check::compare(&scene, &bvh, &reference, res)))
}

fn print_summary(s: &CompareSummary) {
    println!("scene              {}", s.scene);
    println!("triangles          {}", s.triangles);
    println!(
        "rays               {} ({} primary, {} shadow, {} reflection)",
        s.rays, s.primary_rays, s.shadow_rays, s.reflection_rays
    );
    println!("hit mismatch       {}", s.hit_mismatch);
    println!("prim mismatch      {}", s.prim_mismatch);
    println!("t mismatch         {}", s.t_mismatch);
    println!("occlusion mismatch {}", s.occlusion_mismatch);
    println!("max rel t error    {:.3e}", s.max_rel_t_error);
    println!("  primary rays     {:.3e}", s.max_rel_t_error_primary);
    println!("max uv error       {:.3e}", s.max_uv_error);
    println!("ours_wrong         {}", s.ours_wrong);
    println!("embree_wrong       {}", s.embree_wrong);
    println!("ambiguous          {}", s.ambiguous);
    println!("ours_t_off         {}", s.ours_t_off);
    println!("embree_t_off       {}", s.embree_t_off);
    println!("hit agreement      {:.5}%", 100.0 * s.hit_agreement);
    println!("prim agreement     {:.4}%", 100.0 * s.prim_agreement);
}

fn run_stability(
    quick: bool,
    filter: Option<&str>,
    threads: Option<usize>,
    json: Option<PathBuf>,
) -> anyhow::Result<()> {
    let pool = thread_pool(threads)?;
    let device = embree_device(pool.current_num_threads())?;
    let context = stability::Context {
        device: &device,
        quick,
    };
    let results = pool.install(|| stability::run_catalogue(&context, filter));
    print!("{}", stability::table::to_text(&results));
    if let Some(path) = json {
        std::fs::write(&path, serde_json::to_string_pretty(&results)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
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

fn run_render(
    scene: &Scene,
    backend: BackendArg,
    builder: BuilderArg,
    settings: RenderSettings,
    threads: Option<usize>,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    let pool = thread_pool(threads)?;
    let image = match backend {
        BackendArg::Ours => {
            let bvhs = layered::build_bvhs(scene, &builder.options());
            let layers: Vec<&Bvh> = bvhs.iter().collect();
            pool.install(|| render_layers(scene, &layers, &settings))
        }
        BackendArg::Embree | BackendArg::Checked => {
            let device = embree_device(pool.current_num_threads())?;
            let reference = layered::build_embree_scenes(&device, scene, REFERENCE_OPTIONS)?;
            if backend == BackendArg::Embree {
                let layers: Vec<&_> = reference.iter().collect();
                pool.install(|| render_layers(scene, &layers, &settings))
            } else {
                let bvhs = layered::build_bvhs(scene, &builder.options());
                let run =
                    pool.install(|| layered::render_checked(scene, &bvhs, &reference, &settings));
                let log = run
                    .logs
                    .iter()
                    .fold(CheckLog::default(), |a, b| a.merge(b.clone()));
                let verdicts = run.verdicts;
                println!(
                    "checked {} closest-hit and {} any-hit queries: {} differences \
                     (ours_wrong {}, embree_wrong {}, ambiguous {}), max rel t error {:.3e}",
                    log.intersect_queries,
                    log.occluded_queries,
                    log.differences.len(),
                    verdicts.ours_wrong,
                    verdicts.embree_wrong,
                    verdicts.ambiguous,
                    log.max_rel_t_error
                );
                run.image
            }
        }
    };
    image.save(output)?;
    println!("wrote {}", output.display());
    Ok(())
}

/// Draws a debug view of `scene` on our BVH or on Embree; prints its legend.
fn run_debug(
    scene: &Scene,
    backend: BackendArg,
    builder: BuilderArg,
    view: DebugView,
    settings: RenderSettings,
    threads: Option<usize>,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    let pool = thread_pool(threads)?;
    let debug = match backend {
        BackendArg::Ours => {
            let bvhs = layered::build_bvhs(scene, &builder.options());
            let layers: Vec<&Bvh> = bvhs.iter().collect();
            pool.install(|| render_debug(scene, &layers, Some(&bvhs), view, &settings))?
        }
        BackendArg::Embree => {
            let device = embree_device(pool.current_num_threads())?;
            let reference = layered::build_embree_scenes(&device, scene, REFERENCE_OPTIONS)?;
            let layers: Vec<&_> = reference.iter().collect();
            pool.install(|| render_debug(scene, &layers, None, view, &settings))?
        }
        BackendArg::Checked => {
            anyhow::bail!("debug views run on --backend ours or --backend embree, not checked")
        }
    };
    debug.image.save(output)?;
    println!("{view}: {}", debug.legend);
    println!("wrote {}", output.display());
    Ok(())
}
