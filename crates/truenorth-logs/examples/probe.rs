//! Prints what each log (ULog or MCAP) holds and how long it takes to read:
//! `cargo run --release -p truenorth-logs --example probe -- FILE...`.

use std::time::Instant;
use truenorth_logs::{LogConfig, LogReader};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for path in std::env::args().skip(1) {
        let bytes = std::fs::read(&path)?;
        for accept in [false, true] {
            let reader = LogReader::new(LogConfig {
                accept_incomplete: accept,
                ..LogConfig::default()
            })?;
            let start = Instant::now();
            match reader.read_bytes(&bytes) {
                Ok(r) => {
                    let ms = start.elapsed().as_secs_f64() * 1e3;
                    println!(
                        "{path}: {} bytes, read in {ms:.1} ms, complete {}",
                        bytes.len(),
                        r.complete
                    );
                    for t in &r.topics {
                        println!("  topic {t}");
                    }
                    for s in &r.streams {
                        println!("  stream {s:?}");
                    }
                    if let (Some(a), Some(b)) = (r.imu.first(), r.imu.last()) {
                        println!("  imu {:.3}..{:.3} s, first {:?}", a.t_s, b.t_s, a);
                    }
                    if let Some(m) = r.mag.first() {
                        println!("  mag first {m:?}");
                    }
                    break;
                }
                Err(e) => println!("{path} (accept_incomplete {accept}): {e}"),
            }
        }
    }
    Ok(())
}
