//! Where a method's held-out error sits in time: 100 s means of (compensated output − noise)
//! for one family unit, one held-out profile, every `--every` seconds.
//!
//! `generalisation_debug UNIT_SEED PROFILE METHOD[,METHOD] [--every 500]`

use gyrotherm::compensate::compensate_log;
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::{fit_model, FitConfig, NamedLog, RecipeSettings};
use gyrotherm::model::Method;
use gyrotherm::sim::{random_unit, simulate_series, SimConfig, SimSeries};

fn sim(unit_seed: u64, profile: &str, seed: u64, table: bool) -> SimSeries {
    let mut c = SimConfig::builtin(profile).expect("profile");
    c.unit = random_unit(unit_seed);
    c.seed = seed;
    c.table_rate_dps = table.then_some(20.0);
    simulate_series(&c).expect("simulate")
}

fn log(s: &SimSeries) -> TestLog {
    TestLog {
        time_s: s.time_s.clone(),
        gyro_dps: s.gyro_dps.clone(),
        temp_c: s.temp_c.clone(),
        table_dps: s.table_dps.clone(),
        extra: Vec::new(),
    }
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let unit_seed: u64 = a[0].parse().expect("unit seed");
    let profile = a[1].clone();
    let every: usize = a
        .iter()
        .position(|x| x == "--every")
        .and_then(|i| a.get(i + 1))
        .map_or(500, |v| v.parse().expect("--every"));
    println!("{:?}", random_unit(unit_seed));
    let s0 = unit_seed * 100;
    let tr = [
        log(&sim(unit_seed, "seed-shock", s0 + 1, false)),
        log(&sim(unit_seed, "seed-shock", s0 + 2, true)),
    ];
    let names = ["static", "table"];
    let named: Vec<NamedLog> = tr
        .iter()
        .zip(names)
        .map(|(log, name)| NamedLog { name, log })
        .collect();
    let test = sim(unit_seed, &profile, s0 + 51, false);
    let mut cols = Vec::new();
    for m in a[2].split(',') {
        let mut cfg = match m {
            "linear" => FitConfig::new(Method::Linear),
            "poly" => FitConfig::new(Method::Poly),
            _ => FitConfig::new(Method::Lstm),
        };
        if let Ok(k) = Method::parse_recipe(m) {
            cfg.recipe = RecipeSettings::of_kind(k);
            cfg.thermal.basis = gyrotherm::fit::thermal::Basis::Lean;
            cfg.thermal.min_lag_ratio = 3.0;
            cfg.thermal.joint = true;
        }
        let fit = fit_model(&named, &cfg, &|_, _, _| {}).expect("fit");
        if let Some(t) = &fit.bias_training {
            println!("{m}: {:?}", t.thermal);
        }
        if let Some(t) = &fit.scale_training {
            println!("{m} scale: {:?}", t.thermal);
        }
        let same = profile == "seed-shock";
        let table = sim(
            unit_seed,
            &profile,
            if same { s0 + 2 } else { s0 + 52 },
            true,
        );
        let ct = compensate_log(&fit.model, &log(&table)).expect("compensate table");
        let rep = gyrotherm::metrics::scale_factor::scale_factor(
            &table.time_s,
            &ct.gyro_comp_dps,
            table.table_dps.as_deref().unwrap_or_default(),
            &Default::default(),
        )
        .expect("sf");
        println!(
            "{m}: SF thermal error {:.1} ppm (in-sample: {same}); K(t) ppm: {}",
            rep.sf_thermal_error_ppm,
            rep.scale_over_time
                .iter()
                .step_by(4)
                .map(|k| format!("{:.0}", k.deviation_ppm))
                .collect::<Vec<_>>()
                .join(" ")
        );
        let c = compensate_log(&fit.model, &log(&test)).expect("compensate");
        let r: Vec<f64> = c
            .gyro_comp_dps
            .iter()
            .zip(&test.noise_dps)
            .map(|(g, n)| (g - n) * 3600.0)
            .collect();
        cols.push((m.to_owned(), r));
    }
    let mean_all: Vec<f64> = cols
        .iter()
        .map(|(_, r)| r.iter().sum::<f64>() / r.len() as f64)
        .collect();
    print!("{:>7} {:>7} {:>7}", "t_s", "T_c", "coil");
    for (m, _) in &cols {
        print!(" {m:>9}");
    }
    println!(" {:>9}", "truth");
    let tb: Vec<f64> = test.true_bias_dps.iter().map(|b| b * 3600.0).collect();
    let tbm = tb.iter().sum::<f64>() / tb.len() as f64;
    let mut i = 0;
    while i + 100 <= test.time_s.len() {
        print!(
            "{:>7.0} {:>7.2} {:>7.2}",
            test.time_s[i], test.temp_c[i], test.coil_c[i]
        );
        for ((_, r), m) in cols.iter().zip(&mean_all) {
            print!(" {:>9.4}", r[i..i + 100].iter().sum::<f64>() / 100.0 - m);
        }
        println!(" {:>9.4}", tb[i..i + 100].iter().sum::<f64>() / 100.0 - tbm);
        i += every;
    }
}
