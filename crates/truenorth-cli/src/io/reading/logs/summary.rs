//! The lines `inspect` prints about a log before its report, and their JSON.

use truenorth::core::Fixed;
use truenorth_logs::{LogFormat, Recording};

use super::LogInput;

/// The lines `inspect` prints about a log before its report: the format, every topic with
/// its messages (and its mean rate over the recording), the streams read and the options
/// that choose others.
pub fn summary(log: &LogInput) -> Vec<String> {
    let r = &log.recording;
    let mut lines = vec![format!(
        "log: {} ({}), {}",
        log.path.display(),
        r.format,
        if r.complete {
            "complete"
        } else {
            "incomplete: read up to the damage"
        }
    )];
    let span_s = span_s(r);
    lines.push(format!("topics ({}):", r.topics.len()));
    for t in &r.topics {
        let rate = if span_s > 0.0 && t.messages > 1 {
            format!(", {} Hz mean", Fixed(t.messages as f64 / span_s, 1))
        } else {
            String::new()
        };
        lines.push(format!(
            "  {} ({}, {} messages{rate})",
            t.name, t.kind, t.messages
        ));
    }
    lines.push("streams read:".to_string());
    for s in &r.streams {
        lines.push(format!(
            "  {}: {}, {} samples, {} Hz (median step), {} left out",
            s.role,
            s.topic,
            s.samples,
            Fixed(s.rate_hz, 2),
            s.dropped
        ));
    }
    let options = match r.format {
        LogFormat::Ulog => {
            "--imu-topic NAME[:INSTANCE], --mag-topic NAME[:INSTANCE] or none, --attitude-topic NAME[:INSTANCE], --gnss-topic NAME[:INSTANCE] or none"
        }
        LogFormat::Mcap => {
            "--imu-topic TOPIC, --mag-topic TOPIC or none, --attitude-topic TOPIC, --odometry-topic TOPIC, --gnss-topic TOPIC, --gnss-velocity-topic TOPIC"
        }
    };
    lines.push(format!("other streams: {options} (names as listed above)"));
    lines
}

/// [`summary`] as JSON: `format`, `complete`, `topics` (name, kind, messages) and `streams`
/// (role, topic, samples, rate_hz, dropped).
pub fn summary_json(log: &LogInput) -> serde_json::Value {
    let r = &log.recording;
    serde_json::json!({
        "format": r.format.to_string(),
        "complete": r.complete,
        "topics": r.topics.iter().map(|t| serde_json::json!({
            "name": t.name, "kind": t.kind, "messages": t.messages,
        })).collect::<Vec<_>>(),
        "streams": r.streams.iter().map(|s| serde_json::json!({
            "role": s.role, "topic": s.topic, "samples": s.samples,
            "rate_hz": s.rate_hz, "dropped": s.dropped,
        })).collect::<Vec<_>>(),
    })
}

/// The time the selected streams cover, s.
fn span_s(r: &Recording) -> f64 {
    let times = r
        .imu
        .iter()
        .map(|s| s.t_s)
        .chain(r.mag.iter().map(|s| s.t_s))
        .chain(r.attitude.iter().map(|s| s.t_s))
        .chain(r.odometry.iter().map(|s| s.t_s));
    let (lo, hi) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    if hi > lo { hi - lo } else { 0.0 }
}
