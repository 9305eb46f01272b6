//! Reports of GPU timestamp scopes: a text table and Chrome trace-event JSON.

use serde_json::json;

/// One timed pass of one frame, in ns relative to the frame's first timestamp.
#[derive(Clone, Debug)]
pub struct Scope {
    pub name: String,
    pub begin_ns: f64,
    pub end_ns: f64,
}

#[derive(Clone, Debug)]
pub struct ProfileReport {
    pub device: String,
    /// Scopes of each frame, in submission order.
    pub frames: Vec<Vec<Scope>>,
}

impl ProfileReport {
    /// The report of `frames` as the renderer timed them on `device`.
    pub fn from_frames(device: &str, frames: Vec<Vec<crate::vk::TimedScope>>) -> ProfileReport {
        let scope = |s: crate::vk::TimedScope| Scope { name: s.name, begin_ns: s.begin_ns, end_ns: s.end_ns };
        ProfileReport {
            device: device.to_string(),
            frames: frames.into_iter().map(|f| f.into_iter().map(scope).collect()).collect(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct PassStats {
    pub name: String,
    pub mean_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
    /// Mean pass time over mean frame time.
    pub share: f64,
}

/// Frame time: from the first scope's begin to the last scope's end.
fn frame_ns(frame: &[Scope]) -> f64 {
    let begin = frame.iter().map(|s| s.begin_ns).fold(f64::INFINITY, f64::min);
    let end = frame.iter().map(|s| s.end_ns).fold(f64::NEG_INFINITY, f64::max);
    if frame.is_empty() {
        0.0
    } else {
        end - begin
    }
}

/// Per-pass statistics in the order passes first appear, then a `frame` row.
pub fn summary(report: &ProfileReport) -> Vec<PassStats> {
    let mut names: Vec<&str> = Vec::new();
    for s in report.frames.iter().flatten() {
        if !names.contains(&s.name.as_str()) {
            names.push(&s.name);
        }
    }
    let frame_ms: Vec<f64> = report.frames.iter().map(|f| frame_ns(f) / 1e6).collect();
    let mean_frame = frame_ms.iter().sum::<f64>() / frame_ms.len().max(1) as f64;
    let stats = |name: &str, samples: Vec<f64>| {
        let n = samples.len().max(1) as f64;
        let mean = samples.iter().sum::<f64>() / n;
        PassStats {
            name: name.to_string(),
            mean_ms: mean,
            min_ms: samples.iter().copied().fold(f64::INFINITY, f64::min),
            max_ms: samples.iter().copied().fold(0.0, f64::max),
            share: if mean_frame > 0.0 { mean / mean_frame } else { 0.0 },
        }
    };
    let mut rows: Vec<PassStats> = names
        .iter()
        .map(|name| {
            // A pass that runs several times in a frame (tiles) counts as its sum in that frame.
            let samples = report
                .frames
                .iter()
                .map(|f| f.iter().filter(|s| s.name == *name).map(|s| (s.end_ns - s.begin_ns) / 1e6).sum())
                .collect();
            stats(name, samples)
        })
        .collect();
    rows.push(stats("frame", frame_ms));
    rows
}

pub fn format_table(report: &ProfileReport) -> String {
    let rows = summary(report);
    let width = rows.iter().map(|r| r.name.len()).max().unwrap_or(5).max(5);
    let mut out = format!("GPU profile: {}, {} frame(s)\n", report.device, report.frames.len());
    out += &format!("{:<width$}  {:>10}  {:>10}  {:>10}  {:>6}\n", "pass", "mean ms", "min ms", "max ms", "share");
    for r in rows {
        out += &format!(
            "{:<width$}  {:>10.3}  {:>10.3}  {:>10.3}  {:>5.1}%\n",
            r.name,
            r.mean_ms,
            r.min_ms,
            r.max_ms,
            r.share * 100.0
        );
    }
    out
}

/// Chrome trace-event JSON (Perfetto, chrome://tracing): frames laid end to end on one track.
pub fn chrome_trace_json(report: &ProfileReport) -> String {
    let mut events = vec![json!({
        "name": "process_name", "ph": "M", "pid": 1, "tid": 1,
        "args": { "name": format!("GPU: {}", report.device) }
    })];
    let mut offset_us = 0.0;
    for (i, frame) in report.frames.iter().enumerate() {
        let origin = frame.iter().map(|s| s.begin_ns).fold(f64::INFINITY, f64::min);
        for s in frame {
            events.push(json!({
                "name": s.name, "cat": "gpu", "ph": "X", "pid": 1, "tid": 1,
                "ts": offset_us + (s.begin_ns - origin) / 1e3,
                "dur": ((s.end_ns - s.begin_ns) / 1e3).max(0.001),
                "args": { "frame": i }
            }));
        }
        offset_us += frame_ns(frame) / 1e3 + 1.0;
    }
    serde_json::to_string_pretty(&json!({ "traceEvents": events, "displayTimeUnit": "ms" }))
        .expect("JSON of numbers and strings")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scope(name: &str, b: f64, e: f64) -> Scope {
        Scope { name: name.into(), begin_ns: b, end_ns: e }
    }

    #[test]
    fn summary_of_known_frames() {
        let report = ProfileReport {
            device: "test".into(),
            frames: vec![
                vec![scope("a", 0.0, 1e6), scope("b", 1e6, 4e6)],
                vec![scope("a", 0.0, 3e6), scope("b", 3e6, 4e6)],
            ],
        };
        let rows = summary(&report);
        assert_eq!(rows.len(), 3);
        assert_eq!((rows[0].name.as_str(), rows[0].mean_ms, rows[0].min_ms, rows[0].max_ms), ("a", 2.0, 1.0, 3.0));
        assert_eq!((rows[1].mean_ms, rows[1].min_ms, rows[1].max_ms), (2.0, 1.0, 3.0));
        assert_eq!((rows[2].name.as_str(), rows[2].mean_ms), ("frame", 4.0));
        assert!((rows[0].share - 0.5).abs() < 1e-12);
        let table = format_table(&report);
        assert!(table.contains("frame") && table.contains("2.000"));
    }

    #[test]
    fn trace_json_parses() {
        let report = ProfileReport { device: "d".into(), frames: vec![vec![scope("shade", 10.0, 2010.0)]] };
        let v: serde_json::Value = serde_json::from_str(&chrome_trace_json(&report)).unwrap();
        let events = v["traceEvents"].as_array().unwrap();
        let shade = events.iter().find(|e| e["name"] == "shade").unwrap();
        assert_eq!(shade["ph"], "X");
        assert!((shade["dur"].as_f64().unwrap() - 2.0).abs() < 1e-9);
    }
}
