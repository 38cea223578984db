//! When a slower build pays for itself: with build time `B` and time per
//! frame `F`, rendering `N` frames costs `B + N·F` in all. A choice that
//! builds longer but traces faster than another is cheaper in total from
//! `N = ΔB / −ΔF` frames on. Over all choices, the cheapest total at each
//! `N` is the lower envelope of these lines: the Pareto frontier of build
//! time against frame time, walked from few frames to many.

use serde::Serialize;

/// What one choice costs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Cost {
    pub build_seconds: f64,
    pub frame_seconds: f64,
}

impl Cost {
    /// Build plus `frames` frames.
    pub fn total(&self, frames: f64) -> f64 {
        self.build_seconds + frames * self.frame_seconds
    }
}

/// How a choice compares with the next cheaper build.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Overtaking {
    /// The index of the choice with the longest build still shorter than
    /// this one's.
    pub next_cheaper: usize,
    /// The frame count from which this choice's total is lower; `None`
    /// when it traces no faster, so it never is.
    pub frames: Option<f64>,
}

/// Per choice, in order, how it overtakes the next cheaper build; `None`
/// for the cheapest build (and any tied with it).
pub fn overtaking(costs: &[Cost]) -> Vec<Option<Overtaking>> {
    costs
        .iter()
        .map(|c| {
            let next_cheaper = (0..costs.len())
                .filter(|&j| costs[j].build_seconds < c.build_seconds)
                .max_by(|&a, &b| costs[a].build_seconds.total_cmp(&costs[b].build_seconds))?;
            Some(Overtaking {
                next_cheaper,
                frames: crossing(&costs[next_cheaper], c),
            })
        })
        .collect()
}

/// The frame count from which `slower_build` is cheaper in total than
/// `cheaper_build`, if it ever is.
fn crossing(cheaper_build: &Cost, slower_build: &Cost) -> Option<f64> {
    let saved_per_frame = cheaper_build.frame_seconds - slower_build.frame_seconds;
    (saved_per_frame > 0.0)
        .then(|| (slower_build.build_seconds - cheaper_build.build_seconds) / saved_per_frame)
}

/// One stretch of the frontier: the cheapest choice in total from
/// `from_frames` up to `to_frames` (`None`: for ever after).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FrontierSpan {
    pub choice: usize,
    pub from_frames: f64,
    pub to_frames: Option<f64>,
}

/// The cheapest choice in total for every frame count from 0 on, as
/// spans in order. Ties go to the faster frame, which stays cheapest longer.
///
/// # Panics
/// If `costs` is empty or holds a value that is not finite.
pub fn frontier(costs: &[Cost]) -> Vec<FrontierSpan> {
    assert!(
        !costs.is_empty()
            && costs
                .iter()
                .all(|c| c.build_seconds.is_finite() && c.frame_seconds.is_finite()),
        "a frontier needs finite costs: {costs:?}"
    );
    let by = |key: fn(&Cost) -> (f64, f64)| {
        move |&a: &usize, &b: &usize| {
            let (a, b) = (key(&costs[a]), key(&costs[b]));
            a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1))
        }
    };
    let mut current = (0..costs.len())
        .min_by(by(|c| (c.build_seconds, c.frame_seconds)))
        .expect("not empty");
    let mut spans = vec![FrontierSpan {
        choice: current,
        from_frames: 0.0,
        to_frames: None,
    }];
    // Each step moves to a strictly faster frame, so the walk ends.
    while let Some((next, at)) = (0..costs.len())
        .filter_map(|j| Some((j, crossing(&costs[current], &costs[j])?)))
        .min_by(|a, b| {
            a.1.total_cmp(&b.1).then(
                costs[a.0]
                    .frame_seconds
                    .total_cmp(&costs[b.0].frame_seconds),
            )
        })
    {
        let at = at.max(spans.last().map_or(0.0, |s| s.from_frames));
        if let Some(last) = spans.last_mut() {
            last.to_frames = Some(at);
        }
        spans.push(FrontierSpan {
            choice: next,
            from_frames: at,
            to_frames: None,
        });
        current = next;
    }
    spans
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cost(build: f64, frame: f64) -> Cost {
        Cost {
            build_seconds: build,
            frame_seconds: frame,
        }
    }

    #[test]
    fn break_even_frames_on_synthetic_costs() {
        let costs = [
            cost(1.0, 1.0),   // 0: the cheapest build
            cost(3.0, 0.5),   // 1: next cheaper is 2, +1 s, −1.5 s a frame
            cost(2.0, 2.0),   // 2: builds and traces slower than 0
            cost(13.0, 0.25), // 3: next cheaper is 4, +9 s, −0.2 s a frame
            cost(4.0, 0.45),  // 4: next cheaper is 1, +1 s, −0.05 s a frame
        ];
        let over = overtaking(&costs);
        assert_eq!(over[0], None);
        let at = |i: usize| over[i].unwrap();
        assert_eq!(at(2).next_cheaper, 0);
        assert_eq!(at(2).frames, None, "slower to build and to trace");
        assert_eq!(at(1).next_cheaper, 2);
        assert_eq!(at(1).frames, Some(1.0 / 1.5));
        assert_eq!((at(4).next_cheaper, at(3).next_cheaper), (1, 4));
        assert!((at(4).frames.unwrap() - 20.0).abs() < 1e-9);
        assert!((at(3).frames.unwrap() - 9.0 / 0.2).abs() < 1e-9);

        // The envelope: 0 until 1 overtakes it at 2/0.5 = 4 frames; 1 until
        // 4 does at 20 (before 3 would, at 10/0.25 = 40); 4 until 3 does at
        // 45; 2 never leads. Where one span ends the next starts at equal
        // totals.
        let spans = frontier(&costs);
        for pair in spans.windows(2) {
            let (a, b) = (costs[pair[0].choice], costs[pair[1].choice]);
            let at = pair[0].to_frames.unwrap();
            assert!((a.total(at) - b.total(at)).abs() < 1e-9);
        }
        assert_eq!(
            spans.iter().map(|s| s.choice).collect::<Vec<_>>(),
            [0, 1, 4, 3]
        );
        assert_eq!(spans[0].to_frames, Some(4.0));
        assert!((spans[1].to_frames.unwrap() - 20.0).abs() < 1e-9);
        assert!((spans[2].to_frames.unwrap() - 45.0).abs() < 1e-9);
        assert_eq!(spans[3].to_frames, None);
        // At every frame count the frontier's choice is the cheapest.
        for frames in [0.0, 1.0, 3.9, 4.1, 19.0, 21.0, 44.0, 46.0, 1e6] {
            let best = costs
                .iter()
                .map(|c| c.total(frames))
                .fold(f64::INFINITY, f64::min);
            let span = spans
                .iter()
                .find(|s| frames >= s.from_frames && s.to_frames.is_none_or(|t| frames <= t))
                .unwrap();
            assert!((costs[span.choice].total(frames) - best).abs() < 1e-9);
        }
    }

    #[test]
    fn one_choice_is_the_whole_frontier() {
        let spans = frontier(&[cost(0.1, 0.2)]);
        assert_eq!(
            spans,
            [FrontierSpan {
                choice: 0,
                from_frames: 0.0,
                to_frames: None
            }]
        );
    }
}
