//! The dataflash reader on arbitrary bytes, the gyro instance picked by the first byte.
//!
//! Holds: no panic; a log it reads has rows of finite numbers at strictly increasing times,
//! whose sample counts add up to the samples read; an error names the source.

#![no_main]

use std::path::Path;

use gyrotherm::csvlog::{read_unit_from, LogFormat, SAMPLES_COL};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&sel, bytes)) = data.split_first() else {
        return;
    };
    let source = Path::new("<fuzz>");
    match read_unit_from(bytes, source, LogFormat::DataFlash, sel & 3) {
        Ok((log, report)) => {
            assert!(!log.is_empty());
            assert!(log.time_s.windows(2).all(|w| w[0] < w[1]));
            for s in log.gyro.iter().chain(&log.temp) {
                assert_eq!(s.values.len(), log.len());
                assert!(s.values.iter().all(|v| v.is_finite()), "{}", s.name);
            }
            let counts = log.extra.iter().find(|c| c.name == SAMPLES_COL).unwrap();
            let total: u64 = counts.values.iter().map(|v| v.parse::<u64>().unwrap()).sum();
            assert_eq!(total, report.rows);
        }
        Err(e) => assert_eq!(e.path, source),
    }
});
