//! Embree's own statistics about the BVH it builds for a scene.
//!
//! Embree has no API for them; it prints them. [`bvh_statistics`] builds the
//! scene on a private device created with `verbose=2,benchmark=1`, captures
//! standard output meanwhile (see `stdout_capture`), and parses the report
//! of the build: the `building <type> using <builder>` line, the
//! `finished <type> : <ms>ms, ...` line, `primitives = .., vertices = ..,
//! depth = ..`, one row per node group (`<name> : sah = .., #bytes = ..,
//! #nodes = .. (..% filled), #bytes/prim = ..`), the leaf `histogram` row,
//! and `BENCHMARK_BUILD <seconds> <prims/s> <sah> <bytes> <type>` (which
//! gives the SAH cost and byte count at full precision). If a commit prints
//! several builds, the last one (the whole scene's) is taken. Anything
//! missing or malformed is an error carrying the captured text.

use crate::stdout_capture::capture_stdout;
use crate::{Device, DeviceConfig, EmbreeError, Isa, SceneOptions, TriangleMeshRef};

/// One BVH build as Embree reports it.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhStatistics {
    /// E.g. `BVH8<triangle4>` (`triangle4v` with the robust flag).
    pub bvh_type: String,
    /// E.g. `avx::BVH8BuilderSAH`.
    pub builder: String,
    pub build_ms: f64,
    pub primitives: usize,
    pub depth: u32,
    /// Embree's SAH cost of the whole tree.
    pub sah_cost: f64,
    /// Bytes of nodes and leaves.
    pub bytes: usize,
    /// Inner node kinds, then `leaves`, in Embree's order.
    pub node_groups: Vec<NodeGroupStatistics>,
    /// Share of leaves holding 1, 2, ... primitive blocks, in percent.
    pub leaf_histogram_percent: Vec<f64>,
}

/// One row of Embree's per-node-kind table.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeGroupStatistics {
    /// E.g. `getAABBNodes` or `leaves`.
    pub name: String,
    pub sah_cost: f64,
    pub nodes: usize,
    /// How full the nodes' child (or primitive) slots are, in percent.
    pub fill_percent: f64,
    pub bytes_per_primitive: f64,
}

/// The node group Embree calls its leaves.
const LEAVES: &str = "leaves";

impl BvhStatistics {
    /// Inner nodes over all inner node kinds.
    pub fn inner_nodes(&self) -> usize {
        self.node_groups
            .iter()
            .filter(|group| group.name != LEAVES)
            .map(|group| group.nodes)
            .sum()
    }

    /// Leaf nodes.
    pub fn leaf_nodes(&self) -> usize {
        self.node_groups
            .iter()
            .filter(|group| group.name == LEAVES)
            .map(|group| group.nodes)
            .sum()
    }
}

/// Builds `meshes` once on a private, verbose device (`threads` as in
/// [`DeviceConfig`]) and returns Embree's statistics of that build.
pub fn bvh_statistics(
    threads: Option<usize>,
    meshes: &[TriangleMeshRef<'_>],
    options: SceneOptions,
) -> Result<BvhStatistics, EmbreeError> {
    let config = DeviceConfig {
        threads,
        verbose: 2,
        ..DeviceConfig::default()
    };
    let config = format!("{},benchmark=1", config.config_string());
    let (built, output) = capture_stdout(|| {
        let device = Device::from_config_string(config, Isa::Auto)?;
        device.build_scene(meshes, options).map(drop)
    })?;
    built?;
    parse_build_report(&output)
}

/// Parses the last build report in `output`.
pub(crate) fn parse_build_report(output: &str) -> Result<BvhStatistics, EmbreeError> {
    let fail = |reason: String| EmbreeError::StatisticsParse {
        reason,
        output: output.to_owned(),
    };
    let mut lines: Vec<&str> = output.lines().map(str::trim).collect();
    // Descriptor 1 is the process's: text another thread wrote while it was
    // captured (a test harness's status line) may stand before `building`
    // on its line.
    let start = lines
        .iter()
        .rposition(|line| line.contains("building ") && line.contains(" using "))
        .ok_or_else(|| fail("no `building ...` line".into()))?;
    let building = lines[start]
        .find("building ")
        .expect("the line was found by it");
    lines[start] = &lines[start][building..];
    let report = &lines[start..];

    let (bvh_type, builder) = report[0]
        .strip_prefix("building ")
        .and_then(|rest| rest.strip_suffix(" ..."))
        .and_then(|rest| rest.split_once(" using "))
        .ok_or_else(|| fail(format!("unexpected line `{}`", report[0])))?;
    let build_ms = find_line(report, &format!("finished {bvh_type} :"))
        .and_then(|rest| rest.split(',').next())
        .and_then(|ms| ms.trim().strip_suffix("ms"))
        .and_then(|ms| ms.trim().parse().ok())
        .ok_or_else(|| fail("no build time on a `finished` line".into()))?;
    let counts = find_line(report, "primitives =")
        .map(|rest| format!("primitives ={rest}"))
        .ok_or_else(|| fail("no `primitives = ..` line".into()))?;
    let primitives = key_value(&counts, "primitives")
        .ok_or_else(|| fail("unreadable primitive count".into()))?;
    let depth = key_value(&counts, "depth").ok_or_else(|| fail("unreadable tree depth".into()))?;

    let benchmark: Vec<&str> = find_line(report, "BENCHMARK_BUILD")
        .ok_or_else(|| fail("no `BENCHMARK_BUILD` line".into()))?
        .split_whitespace()
        .collect();
    let (sah_cost, bytes) = match benchmark.as_slice() {
        [_, _, sah, bytes, kind] if *kind == bvh_type => (sah.parse().ok(), bytes.parse().ok()),
        _ => (None, None),
    };
    let (Some(sah_cost), Some(bytes)) = (sah_cost, bytes) else {
        return Err(fail("unreadable `BENCHMARK_BUILD` line".into()));
    };

    let node_groups: Vec<NodeGroupStatistics> = report
        .iter()
        .filter_map(|line| line.split_once(':'))
        .filter(|(name, rest)| name.trim() != "total" && rest.contains("sah ="))
        .map(|(name, rest)| parse_node_group(name.trim(), rest))
        .collect::<Option<_>>()
        .ok_or_else(|| fail("unreadable node group row".into()))?;
    if !node_groups.iter().any(|group| group.name == LEAVES) {
        return Err(fail("no `leaves` row".into()));
    }
    let leaf_histogram_percent = find_line(report, "histogram")
        .and_then(|rest| rest.trim_start().strip_prefix(':'))
        .map(|rest| {
            rest.split_whitespace()
                .map(|share| share.strip_suffix('%').and_then(|s| s.parse().ok()))
                .collect::<Option<Vec<f64>>>()
        })
        .and_then(|shares| shares.filter(|shares| !shares.is_empty()))
        .ok_or_else(|| fail("unreadable leaf `histogram` row".into()))?;

    Ok(BvhStatistics {
        bvh_type: bvh_type.to_owned(),
        builder: builder.to_owned(),
        build_ms,
        primitives,
        depth,
        sah_cost,
        bytes,
        node_groups,
        leaf_histogram_percent,
    })
}

/// The rest of the first line holding `prefix`, after it.
fn find_line<'a>(lines: &[&'a str], prefix: &str) -> Option<&'a str> {
    // Anywhere in the line, as the `building` line is found: another
    // thread's output on the same stdout can come first on it (a test
    // harness's `test NAME ... ` did).
    lines
        .iter()
        .find_map(|line| line.find(prefix).map(|at| &line[at + prefix.len()..]))
}

/// The number after `key =` in a comma-separated `key = value` list.
fn key_value<T: std::str::FromStr>(fields: &str, key: &str) -> Option<T> {
    fields.split(',').find_map(|field| {
        let (name, value) = field.split_once('=')?;
        if name.trim() != key {
            return None;
        }
        value.split_whitespace().next()?.parse().ok()
    })
}

/// `sah = S (..%), #bytes = B MB (..%), #nodes = N (F% filled), #bytes/prim = X`.
fn parse_node_group(name: &str, fields: &str) -> Option<NodeGroupStatistics> {
    let fill_percent = fields
        .split(',')
        .find(|field| field.trim_start().starts_with("#nodes"))?
        .split_once('(')?
        .1
        .split_once('%')?
        .0
        .trim()
        .parse()
        .ok()?;
    Some(NodeGroupStatistics {
        name: name.to_owned(),
        sah_cost: key_value(fields, "sah")?,
        nodes: key_value(fields, "#nodes")?,
        fill_percent,
        bytes_per_primitive: key_value(fields, "#bytes/prim")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A report shaped like Embree's, with numbers made up for the test.
    const REPORT: &str = "\
noise before
building BVH4<triangle4> using sse2::BVH4BuilderSAH ...
finished BVH4<triangle4> : 1.5ms, 2 Mprim/s, 0.1 GB/s
  primitives = 12, vertices = 0, depth = 2
  total            : sah =   3.500 (100.00%), #bytes =    0.00 MB (100.00%), #nodes =       5 ( 80.00% filled), #bytes/prim =  90.00
  getAABBNodes     : sah =   1.250 ( 35.71%), #bytes =    0.00 MB ( 30.00%), #nodes =       2 ( 62.50% filled), #bytes/prim =  30.00
  leaves           : sah =   2.250 ( 64.29%), #bytes =    0.00 MB ( 70.00%), #nodes =       3 ( 75.00% filled), #bytes/prim =  60.00
    histogram      :  25.00%  75.00%
  total : used =   0.001 MB, free =   0.000 MB, wasted =   0.000 MB, total =   0.001 MB, #bytes/prim =  99.00
BENCHMARK_BUILD 0.0015 8000 3.5 1080 BVH4<triangle4>
";

    #[test]
    fn parses_every_field_of_a_report() {
        let stats = parse_build_report(REPORT).unwrap();
        assert_eq!(stats.bvh_type, "BVH4<triangle4>");
        assert_eq!(stats.builder, "sse2::BVH4BuilderSAH");
        assert_eq!(stats.build_ms, 1.5);
        assert_eq!((stats.primitives, stats.depth), (12, 2));
        assert_eq!((stats.sah_cost, stats.bytes), (3.5, 1080));
        assert_eq!(stats.node_groups.len(), 2);
        assert_eq!(stats.node_groups[0].name, "getAABBNodes");
        assert_eq!(stats.node_groups[0].fill_percent, 62.5);
        assert_eq!(stats.node_groups[1].bytes_per_primitive, 60.0);
        assert_eq!((stats.inner_nodes(), stats.leaf_nodes()), (2, 3));
        assert_eq!(stats.leaf_histogram_percent, vec![25.0, 75.0]);
    }

    #[test]
    fn a_missing_line_is_an_error_not_a_default() {
        for dropped in [
            "BENCHMARK_BUILD",
            "leaves",
            "histogram",
            "primitives",
            "finished",
        ] {
            let text: String = REPORT
                .lines()
                .filter(|line| !line.contains(dropped))
                .map(|line| format!("{line}\n"))
                .collect();
            let error = parse_build_report(&text).unwrap_err();
            assert!(
                matches!(error, EmbreeError::StatisticsParse { .. }),
                "dropping {dropped}: {error}"
            );
        }
    }

    /// As captured while a test harness wrote its status line to the same
    /// descriptor: the report, with text before `building` and a line of
    /// its own among the report's.
    #[test]
    fn text_written_beside_the_report_is_passed_over() {
        let mixed = REPORT
            .replace("building ", "test other::test ... building ")
            .replace("finished ", "ok\nfinished ");
        let stats = parse_build_report(&mixed).unwrap();
        assert_eq!(stats, parse_build_report(REPORT).unwrap());
    }

    #[test]
    fn the_last_of_several_reports_is_taken() {
        let first = REPORT.replace("depth = 2", "depth = 9");
        let stats = parse_build_report(&format!("{first}{REPORT}")).unwrap();
        assert_eq!(stats.depth, 2);
    }
}
