//! Which instruction set Embree's kernels run on: what a device is asked
//! for (`isa=` in the `rtcNewDevice` configuration, Embree's API docs) and
//! what it selected, as Embree itself reports it.
//!
//! Embree has no API for the selection; it prints it. With `verbose=2` a
//! device prints its configuration (`frequency_level = simd256`, ...) and
//! each scene commit the intersectors it selected
//! (`selected scene intersector` / `intersector1 = avx512::BVH8...`): the
//! namespace of the single-ray intersector is the instruction set that
//! `rtcIntersect1` and `rtcOccluded1` run.

use std::fmt;
use std::str::FromStr;

use crate::EmbreeError;

/// The `isa=` of a device's configuration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Isa {
    /// No `isa=`: Embree takes the widest it was built with and the CPU
    /// has.
    #[default]
    Auto,
    /// `isa=avx2`.
    Avx2,
    /// `isa=avx512`.
    Avx512,
}

/// A name [`Isa`] does not know. Embree itself takes any `isa=` and falls
/// back to SSE2 for one it does not know, so names are checked here.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown Embree ISA '{0}': expected auto, avx2 or avx512")]
pub struct UnknownIsa(pub String);

impl Isa {
    /// The value of `isa=`, or `None` for [`Isa::Auto`].
    pub(crate) fn config_value(self) -> Option<&'static str> {
        match self {
            Isa::Auto => None,
            Isa::Avx2 => Some("avx2"),
            Isa::Avx512 => Some("avx512"),
        }
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.config_value().unwrap_or("auto"))
    }
}

impl FromStr for Isa {
    type Err = UnknownIsa;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        [Isa::Auto, Isa::Avx2, Isa::Avx512]
            .into_iter()
            .find(|isa| isa.to_string() == text)
            .ok_or_else(|| UnknownIsa(text.to_string()))
    }
}

/// The instruction set Embree selected, as its verbose output says.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SelectedIsa {
    /// The namespace of the selected single-ray intersector, e.g. `avx512`.
    pub isa: String,
    /// That intersector, e.g. `avx512::BVH8Triangle4Intersector1Moeller`.
    pub intersector: String,
    /// The device's `frequency_level`, e.g. `simd256` (AVX-512
    /// instructions on 256-bit registers).
    pub frequency_level: String,
}

/// Reads the selection from the output of a `verbose=2` device that
/// committed a scene; anything missing is an error carrying the output.
pub(crate) fn parse_selection(output: &str) -> Result<SelectedIsa, EmbreeError> {
    let fail = |reason: &str| EmbreeError::StatisticsParse {
        reason: reason.to_owned(),
        output: output.to_owned(),
    };
    let value = |line: &str, key: &str| {
        let (name, value) = line.split_once('=')?;
        (name.trim() == key).then(|| value.trim().to_owned())
    };
    let lines: Vec<&str> = output.lines().collect();
    let selected = lines
        .iter()
        .rposition(|line| line.trim() == "selected scene intersector")
        .ok_or_else(|| fail("no `selected scene intersector` block"))?;
    let intersector = lines[selected + 1..]
        .iter()
        .find_map(|line| value(line, "intersector1"))
        .ok_or_else(|| fail("no `intersector1 = ..` line after `selected scene intersector`"))?;
    let isa = intersector
        .split_once("::")
        .map(|(isa, _)| isa.to_owned())
        .filter(|isa| !isa.is_empty())
        .ok_or_else(|| fail("the selected intersector names no instruction set"))?;
    let frequency_level = lines
        .iter()
        .find_map(|line| value(line, "frequency_level"))
        .ok_or_else(|| fail("no `frequency_level = ..` line"))?;
    Ok(SelectedIsa {
        isa,
        intersector,
        frequency_level,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Output shaped like Embree's, trimmed to the lines read.
    const OUTPUT: &str = "\
general:
  build threads      = 0
  frequency_level    = simd256
created scene intersector
  accels[0]
    intersector1  = sse42::Unused
selected scene intersector
  intersector1  = avx512::BVH8Triangle4Intersector1Moeller
  intersector4  = avx512::BVH8Triangle4Intersector4HybridMoellerNoFilter
";

    #[test]
    fn reads_the_selected_intersector_and_the_frequency_level() {
        let selected = parse_selection(OUTPUT).unwrap();
        assert_eq!(selected.isa, "avx512");
        assert_eq!(
            selected.intersector,
            "avx512::BVH8Triangle4Intersector1Moeller"
        );
        assert_eq!(selected.frequency_level, "simd256");
    }

    #[test]
    fn a_missing_line_is_an_error_not_a_guess() {
        for dropped in [
            "selected scene",
            "intersector1  = avx512",
            "frequency_level",
        ] {
            let text: String = OUTPUT
                .lines()
                .filter(|line| !line.contains(dropped))
                .map(|line| format!("{line}\n"))
                .collect();
            let error = parse_selection(&text).unwrap_err();
            assert!(
                matches!(error, EmbreeError::StatisticsParse { .. }),
                "dropping {dropped}: {error}"
            );
        }
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for text in ["auto", "avx2", "avx512"] {
            assert_eq!(text.parse::<Isa>().unwrap().to_string(), text);
        }
        assert_eq!("sse2".parse::<Isa>(), Err(UnknownIsa("sse2".into())));
    }
}
