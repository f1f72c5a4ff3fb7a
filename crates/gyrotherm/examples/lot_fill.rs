//! Fill a lot with synthetic runs (`gyrotherm::lot::synthetic_run`): the benchmark's 1,000-unit
//! lot without simulating 1,000 units. Usage: `lot_fill DB N` (SQLite path or postgres:// URL).

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (db, n) = match args.as_slice() {
        [_, db, n] => (db.as_str(), n.parse::<u64>()?),
        _ => return Err("usage: lot_fill DB N".into()),
    };
    let mut store = gyrotherm::lot::open_store(db, true, 30_000)?;
    let t0 = gyrotherm::lot::now_unix_ms();
    for i in 0..n {
        // One unit every 5 minutes of test time.
        let run = gyrotherm::lot::synthetic_run(&format!("SN{i:05}"), i, t0 + i as i64 * 300_000);
        store.add(&run)?;
    }
    println!("added {n} synthetic runs to {db}");
    Ok(())
}
