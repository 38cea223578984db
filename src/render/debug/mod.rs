//! Debug views: images of what the tracer did rather than of the scene's
//! light, one file per view — the BVH boxes of one level drawn over the
//! render ([`bvh_level`]), nodes visited per pixel ([`heat`]), normals,
//! barycentrics and texture coordinates ([`surface_views`]), the bloom mask
//! ([`bloom_mask`]) and one pixel's rays ([`ray_paths`]); [`draw`] projects
//! and draws lines.
//!
//! Views pick display colours (what the PNG shows, 0.5·n + 0.5 for a
//! normal) and store them through [`display`], so an 8-bit PNG holds
//! exactly those values.

pub mod bloom_mask;
pub mod bvh_level;
pub mod draw;
pub mod heat;
pub mod ray_paths;
pub mod surface_views;

use super::image::{Image, decode_srgb};
use super::{RenderSettings, Renderer};
use crate::bvh::BvhView;
use crate::scene::Scene;
use crate::trace::Intersector;
use anyhow::{Context, bail};
use glam::Vec3;
use std::fmt;
use std::str::FromStr;
use surface_views::Attribute;

/// One debug view, as named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DebugView {
    /// The boxes of the nodes at this depth (root = 0) over the render.
    BvhLevel(u32),
    /// Nodes visited per pixel by closest-hit traversal.
    Heat,
    Normals,
    Barycentrics,
    Texcoords,
    /// Red where the render is above the bloom threshold, blue below.
    BloomMask,
    /// Every ray of pixel (`x`, `y`) over the render.
    Rays {
        x: u32,
        y: u32,
    },
}

/// The accepted spellings, for help texts and errors.
pub const VIEW_SYNTAX: &str =
    "bvh-level=N, heat, normals, barycentrics, texcoords, bloom-mask or rays=X,Y";

impl FromStr for DebugView {
    type Err = anyhow::Error;

    fn from_str(text: &str) -> anyhow::Result<Self> {
        let number = |s: &str, what: &str| {
            s.trim()
                .parse::<u32>()
                .with_context(|| format!("bad {what} '{s}' in debug view '{text}'"))
        };
        Ok(match text.split_once('=') {
            None => match text {
                "heat" => DebugView::Heat,
                "normals" => DebugView::Normals,
                "barycentrics" => DebugView::Barycentrics,
                "texcoords" => DebugView::Texcoords,
                "bloom-mask" => DebugView::BloomMask,
                _ => bail!("unknown debug view '{text}': use {VIEW_SYNTAX}"),
            },
            Some(("bvh-level", level)) => DebugView::BvhLevel(number(level, "level")?),
            Some(("rays", pixel)) => {
                let (x, y) = pixel
                    .split_once(',')
                    .with_context(|| format!("debug view '{text}': expected rays=X,Y"))?;
                DebugView::Rays {
                    x: number(x, "x")?,
                    y: number(y, "y")?,
                }
            }
            Some(_) => bail!("unknown debug view '{text}': use {VIEW_SYNTAX}"),
        })
    }
}

impl fmt::Display for DebugView {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DebugView::BvhLevel(level) => write!(f, "bvh-level={level}"),
            DebugView::Heat => write!(f, "heat"),
            DebugView::Normals => write!(f, "normals"),
            DebugView::Barycentrics => write!(f, "barycentrics"),
            DebugView::Texcoords => write!(f, "texcoords"),
            DebugView::BloomMask => write!(f, "bloom-mask"),
            DebugView::Rays { x, y } => write!(f, "rays={x},{y}"),
        }
    }
}

impl DebugView {
    /// Whether the view reads our BVH's nodes, and so needs our backend.
    pub fn needs_bvh(&self) -> bool {
        matches!(self, DebugView::BvhLevel(_) | DebugView::Heat)
    }
}

/// A debug view's image and the line that says how to read it.
#[derive(Clone, Debug)]
pub struct DebugImage {
    pub image: Image,
    pub legend: String,
}

/// Draws `view` of `scene` through `layers` (one intersector per mesh
/// layer); the views that read BVH nodes also need `bvhs`, our BVH of every
/// layer, binary or wide. Run it inside [`crate::parallel::thread_pool`] to
/// choose the thread count; the image is the same for any.
pub fn render_debug<I: Intersector + ?Sized>(
    scene: &Scene,
    layers: &[&I],
    bvhs: Option<&[&dyn BvhView]>,
    view: DebugView,
    settings: &RenderSettings,
) -> anyhow::Result<DebugImage> {
    let renderer = Renderer::new(scene, layers, settings);
    let our_bvhs = || {
        bvhs.with_context(|| {
            format!("the {view} debug view reads our BVH: render it with --backend ours")
        })
    };
    let render = || super::render_layers(scene, layers, settings);
    Ok(match view {
        DebugView::BvhLevel(level) => bvh_level::draw(scene, render(), our_bvhs()?, level)?,
        DebugView::Heat => heat::draw(scene, our_bvhs()?, settings),
        DebugView::Normals => surface_views::draw(&renderer, Attribute::Normal),
        DebugView::Barycentrics => surface_views::draw(&renderer, Attribute::Barycentrics),
        DebugView::Texcoords => surface_views::draw(&renderer, Attribute::Texcoords),
        DebugView::BloomMask => bloom_mask::draw(&renderer),
        DebugView::Rays { x, y } => ray_paths::draw(&renderer, render(), x, y)?,
    })
}

/// The linear value whose PNG shows the display colour `colour`.
pub fn display(colour: Vec3) -> Vec3 {
    colour.map(decode_srgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_parse_and_print_back() {
        for text in [
            "bvh-level=3",
            "heat",
            "normals",
            "barycentrics",
            "texcoords",
            "bloom-mask",
            "rays=12,40",
        ] {
            let view: DebugView = text.parse().unwrap();
            assert_eq!(view.to_string(), text);
        }
        assert_eq!(
            "rays=1, 2".parse::<DebugView>().unwrap(),
            DebugView::Rays { x: 1, y: 2 }
        );
    }

    #[test]
    fn bad_views_are_clear_errors() {
        for (text, expected) in [
            ("heatmap", "unknown debug view 'heatmap'"),
            ("depth=2", "unknown debug view 'depth=2'"),
            ("bvh-level=-1", "bad level '-1'"),
            ("rays=3", "expected rays=X,Y"),
            ("rays=3,y", "bad y 'y'"),
        ] {
            let error = text.parse::<DebugView>().unwrap_err().to_string();
            assert!(error.contains(expected), "{text}: {error}");
        }
    }
}
