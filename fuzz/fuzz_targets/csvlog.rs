//! The CSV log reader on arbitrary bytes, under options picked by the first byte.
//!
//! Holds: no panic; every sample it gives has finite time, gyro, temperature (and table
//! rate), and time strictly increases; an error names the source.

#![no_main]

use std::io::Cursor;

use gyrotherm::csvlog::{GyroUnit, LogReader, ReadOptions};
use libfuzzer_sys::fuzz_target;

/// Samples read before a case is cut short (gap filling may legitimately make many).
const MAX_SAMPLES: usize = 200_000;

fuzz_target!(|data: &[u8]| {
    let Some((&sel, text)) = data.split_first() else {
        return;
    };
    let opts = ReadOptions {
        gyro_unit: match sel & 3 {
            0 | 3 => GyroUnit::Dps,
            1 => GyroUnit::Dph,
            _ => GyroUnit::RadPerS,
        },
        fill_gaps_max_s: match (sel >> 2) & 3 {
            0 => None,
            1 => Some(5.0),
            2 => Some(1e3),
            _ => Some(0.5),
        },
        sample_period_s: match (sel >> 4) & 3 {
            0 => None,
            1 => Some(1.0),
            2 => Some(0.01),
            _ => Some(0.37),
        },
        table_col: if sel & 0x40 != 0 {
            "table".into()
        } else {
            ReadOptions::default().table_col
        },
        ..ReadOptions::default()
    };
    let mut rdr = match LogReader::new(Cursor::new(text), "fuzz.csv", &opts) {
        Ok(r) => r,
        Err(e) => {
            assert!(e.to_string().contains("fuzz.csv"), "{e}");
            return;
        }
    };
    let mut last_t = f64::NEG_INFINITY;
    for _ in 0..MAX_SAMPLES {
        match rdr.next_sample() {
            Ok(Some(s)) => {
                assert!(s.time_s.is_finite(), "{s:?}");
                assert!(s.gyro_dps.is_finite(), "{s:?}");
                assert!(s.temp_c.is_finite(), "{s:?}");
                assert!(s.table_dps.is_none_or(f64::is_finite), "{s:?}");
                assert!(s.time_s > last_t, "time {} after {last_t}", s.time_s);
                last_t = s.time_s;
            }
            Ok(None) => break,
            Err(e) => {
                assert!(e.to_string().contains("fuzz.csv"), "{e}");
                break;
            }
        }
    }
});
