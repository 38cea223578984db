//! Hits files as a backend: it answers each ray of their rays files with
//! the recorded answer, so `judge` checks a tracer's files exactly as
//! `compare` and `stability` check a built-in tracer.

use super::files::{HitsFile, RaysFile};
use crate::backends::{Answers, Backend};
use crate::check::{Answer, ray_bits};
use crate::geometry::{Hit, Ray};
use crate::trace::Intersector;
use std::collections::HashMap;
use std::time::Duration;

/// The answers of hits files, looked up by the bits of their ray: closest
/// hits from the files of closest-hit sets, occlusion from those of
/// any-hit sets.
pub struct Recorded {
    name: String,
    gives_uv: bool,
    closest: HashMap<[u32; 8], Answer>,
    occluded: HashMap<[u32; 8], Answer>,
}

impl Recorded {
    /// Pairs every ray of each rays file with its answer in the hits file
    /// beside it. A ray asked one query twice must have been answered the
    /// same way twice. The `u`, `v` count as given when every closest-hit
    /// file gives them.
    pub fn new(name: &str, files: &[(&RaysFile, &HitsFile)]) -> anyhow::Result<Self> {
        let mut closest: HashMap<[u32; 8], (usize, Answer)> = HashMap::new();
        let mut occluded = HashMap::new();
        for (rays, hits) in files {
            let answers = if rays.set.is_any_hit() {
                &mut occluded
            } else {
                &mut closest
            };
            for (index, (ray, answer)) in rays.rays.iter().zip(&hits.answers).enumerate() {
                if let Some((first, earlier)) = answers.insert(ray_bits(ray), (index, *answer))
                    && earlier != *answer
                {
                    anyhow::bail!(
                        "rays {first} and {index} are the same ray, answered differently \
                         ({earlier:?} and {answer:?})"
                    );
                }
            }
        }
        let strip = |answers: HashMap<[u32; 8], (usize, Answer)>| {
            answers.into_iter().map(|(k, (_, a))| (k, a)).collect()
        };
        let closest_files = files.iter().filter(|(rays, _)| !rays.set.is_any_hit());
        Ok(Self {
            name: name.to_string(),
            gives_uv: closest_files.clone().count() > 0
                && closest_files.clone().all(|(_, hits)| hits.gives_uv),
            closest: strip(closest),
            occluded: strip(occluded),
        })
    }
}

impl Intersector for Recorded {
    /// The recorded closest hit (a miss for a ray the files do not hold).
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match self.closest.get(&ray_bits(ray)) {
            Some(Answer::Closest(hit)) => *hit,
            _ => None,
        }
    }

    /// The recorded occlusion (not occluded for a ray the files do not
    /// hold).
    fn occluded(&self, ray: &Ray) -> bool {
        matches!(
            self.occluded.get(&ray_bits(ray)),
            Some(Answer::Occluded(true))
        )
    }
}

impl Backend for Recorded {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn answers(&self) -> Answers {
        Answers {
            uv: self.gives_uv,
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
