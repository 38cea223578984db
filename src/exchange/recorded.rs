//! A hits file as a backend: it answers each ray of its rays file with the
//! recorded answer, so `judge` checks it exactly as `compare` checks a
//! tracer.

use super::files::{HitsFile, RaysFile};
use crate::backends::{Answers, Backend};
use crate::check::{Answer, ray_bits};
use crate::geometry::{Hit, Ray};
use crate::trace::Intersector;
use std::collections::HashMap;
use std::time::Duration;

/// The answers of a hits file, looked up by the bits of their ray.
pub struct Recorded {
    name: String,
    gives_uv: bool,
    answers: HashMap<[u32; 8], Answer>,
}

impl Recorded {
    /// Pairs every ray with its answer. A ray asked twice must have been
    /// answered the same way twice.
    pub fn new(name: &str, rays: &RaysFile, hits: &HitsFile) -> anyhow::Result<Self> {
        let mut answers: HashMap<[u32; 8], (usize, Answer)> = HashMap::new();
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
        Ok(Self {
            name: name.to_string(),
            gives_uv: hits.gives_uv,
            answers: answers.into_iter().map(|(k, (_, a))| (k, a)).collect(),
        })
    }

    fn answer(&self, ray: &Ray) -> Option<Answer> {
        self.answers.get(&ray_bits(ray)).copied()
    }
}

impl Intersector for Recorded {
    /// The recorded closest hit (a miss for a ray the file does not hold).
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match self.answer(ray) {
            Some(Answer::Closest(hit)) => hit,
            _ => None,
        }
    }

    /// The recorded occlusion (not occluded for a ray the file does not
    /// hold).
    fn occluded(&self, ray: &Ray) -> bool {
        matches!(self.answer(ray), Some(Answer::Occluded(true)))
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
