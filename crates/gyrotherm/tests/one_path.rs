//! One entry point per job for a single gyro and a unit: a job's logs read through
//! `csvlog::read_log_set`, and `train::train` over them. The single-gyro model `train` makes
//! is checked against `fit_model` called directly (the fit it wraps), and the unit's against
//! `imu_model::fit_imu`.

use std::path::PathBuf;

use gyrotherm::csvlog::{read_log_set, read_log_sets, write_log, LogSetError, ReadOptions};
use gyrotherm::fit::{fit_model, FitConfig, NamedLog};
use gyrotherm::model::unit::ImuModel;
use gyrotherm::model::{ColumnsDef, ModelFile, TempSensorDef};
use gyrotherm::settings::Method;
use gyrotherm::sim::{simulate, SimConfig};
use gyrotherm::told::Told;
use gyrotherm::train::{train, TrainEvent};

fn short_log(seed: u64) -> gyrotherm::TestLog {
    let mut cfg = SimConfig::builtin("seed-shock").unwrap();
    cfg.seed = seed;
    simulate(&cfg).unwrap()
}

#[test]
fn a_set_tells_each_file_and_fails_when_one_cannot_be_read() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.csv");
    // 1 Hz with one sample missing at t = 2: filled when allowed, and told.
    std::fs::write(
        &good,
        "time_s,gyro_dps,temp_c\n0,0,20\n1,0,20\n3,0,20\n4,0,20\n",
    )
    .unwrap();
    let missing = dir.path().join("missing.csv");
    let opts = ReadOptions {
        fill_gaps_max_s: Some(2.0),
        ..ReadOptions::default()
    };
    let read = read_log_set(&[good.clone(), missing.clone()], &opts, None);
    assert_eq!(read.files.len(), 2);
    assert!(read.files[0].error.is_none());
    assert!(
        matches!(&read.files[0].told[..], [Told::Line(l)] if l.contains("filled 1 gap(s)")),
        "{:?}",
        read.files[0].told
    );
    assert!(read.files[1].error.is_some());
    assert_eq!(read.set.unwrap_err(), LogSetError { failed: 1, of: 2 });

    let read = read_log_set(std::slice::from_ref(&good), &opts, None);
    let set = read.set.unwrap();
    assert_eq!(set.names(), [good.display().to_string()]);
    assert_eq!(set.gap_warnings().len(), 1);
}

#[test]
fn the_sets_of_one_job_are_read_alike() {
    // Column lists make every set a unit's; the training and held-out sets are read in one
    // form, so a comparison never meets a single gyro's set beside a unit's.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("u.csv");
    std::fs::write(&p, "time_s,gx,gy,t\n0,0,0,20\n1,0,0,20\n2,0,0,20\n").unwrap();
    let opts = ReadOptions {
        gyro_col: "gx,gy".into(),
        temp_col: "t".into(),
        ..ReadOptions::default()
    };
    let sets = read_log_sets(&[&[p.clone()][..], &[p.clone()][..]], &opts, None);
    for s in sets {
        let set = s.set.unwrap();
        assert_eq!(set.is_static(), [true]);
        assert_eq!(set.len(), 1);
    }
}

#[test]
fn train_on_a_single_gyro_s_set_is_fit_model_with_the_columns_remembered() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.csv");
    let log = short_log(7);
    write_log(&path, &log).unwrap();
    let opts = ReadOptions::default();
    let set = read_log_set(std::slice::from_ref(&path), &opts, None)
        .set
        .unwrap();
    let cfg = FitConfig::new(Method::Linear);
    let trained = train(&set, &cfg, &TempSensorDef::default(), &opts, &|_| {}).unwrap();
    let got = ModelFile::from_json(&trained.model.to_json().unwrap())
        .expect("a single gyro's logs must give a single-gyro model file");

    // The same fit called directly, on the log as read back.
    let (read_back, _) = gyrotherm::read_log(&path, &opts).unwrap();
    let name = path.display().to_string();
    let mut want = fit_model(
        &[NamedLog {
            name: &name,
            log: &read_back,
        }],
        &cfg,
        &|_, _, _| {},
    )
    .unwrap()
    .model;
    want.columns = Some(ColumnsDef::of(&opts));
    assert_eq!(got.to_json().unwrap(), want.to_json().unwrap());
}

#[test]
fn train_on_a_unit_s_set_tells_each_axis_step_with_its_names() {
    let dir = tempfile::tempdir().unwrap();
    let path: PathBuf = dir.path().join("u.csv");
    let a = short_log(1);
    let b = short_log(2);
    let mut text = String::from("time_s,gx,gy,t\n");
    for i in 0..a.len() {
        text.push_str(&format!(
            "{},{},{},{}\n",
            a.time_s[i], a.gyro_dps[i], b.gyro_dps[i], a.temp_c[i]
        ));
    }
    std::fs::write(&path, text).unwrap();
    let opts = ReadOptions {
        gyro_col: "gx,gy".into(),
        temp_col: "t".into(),
        ..ReadOptions::default()
    };
    let set = read_log_set(std::slice::from_ref(&path), &opts, None)
        .set
        .unwrap();
    let steps = std::sync::Mutex::new(Vec::new());
    let cfg = FitConfig::new(Method::Linear);
    let trained = train(&set, &cfg, &TempSensorDef::default(), &opts, &|e| {
        if let TrainEvent::Axis(s) = e {
            steps.lock().unwrap().push((s.gyro, s.temp));
        }
    })
    .unwrap();
    let got = ImuModel::from_json(&trained.model.to_json().unwrap())
        .expect("a unit's logs must give a unit's model file");
    assert_eq!(got.gyro_cols, ["gx", "gy"]);
    let mut steps = steps.into_inner().unwrap();
    steps.sort();
    // Per axis: it starts (no sensor yet), its one sensor starts and finishes, it is done.
    for g in ["gx", "gy"] {
        let of: Vec<_> = steps.iter().filter(|(a, _)| a == g).collect();
        assert_eq!(of.len(), 4, "{steps:?}");
        assert_eq!(of.iter().filter(|(_, t)| t.is_none()).count(), 1);
    }
    // The unit fit called directly gives the same file.
    let (log, _) = gyrotherm::csvlog::read_imu_log(&path, &opts, None).unwrap();
    let want = gyrotherm::fit::unit::fit_imu(
        &[(path.display().to_string(), log)],
        &cfg,
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    assert_eq!(got.to_json().unwrap(), want.to_json().unwrap());
}

#[test]
fn a_single_gyro_model_in_memory_is_a_unit_of_one_axis_with_the_compensator_s_numbers() {
    let log = short_log(9);
    let name = "s".to_owned();
    let file = fit_model(
        &[NamedLog {
            name: &name,
            log: &log,
        }],
        &FitConfig::new(Method::Linear),
        &|_, _, _| {},
    )
    .unwrap()
    .model;
    let model = gyrotherm::unit_model::Model::from_single(file.clone());
    // The text round-trips in its form, with the bytes the file's own code writes.
    let text = model.to_json().unwrap();
    assert_eq!(text, format!("{}\n", file.to_json().unwrap()));
    let back = gyrotherm::unit_model::Model::from_json(&text).unwrap();
    assert_eq!(back.to_json().unwrap(), text);
    // No columns recorded: the standard names.
    let (gyro, temp) = model.columns();
    assert_eq!(
        (gyro.as_slice(), temp.as_slice()),
        (&["gyro_dps".to_owned()][..], &["temp_c".to_owned()][..])
    );

    let series = |name: &str, values: &[f64]| gyrotherm::csvlog::NamedSeries {
        name: name.to_owned(),
        values: values.to_vec(),
    };
    let unit_log = gyrotherm::csvlog::ImuLog {
        time_s: log.time_s.clone(),
        gyro: vec![series("gyro_dps", &log.gyro_dps)],
        temp: vec![series("temp_c", &log.temp_c)],
        ..Default::default()
    };
    let (axes, _) = model.compensate_log(&unit_log).unwrap();
    // Independently: the single-gyro flight compensator stepped over the same samples.
    let mut comp = gyrotherm::compensate::compensator(&file).unwrap();
    assert_eq!(axes.len(), 1);
    for i in 0..log.len() {
        let c = comp.step(log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        assert_eq!(
            axes[0].gyro_comp_dps[i].to_bits(),
            c.rate_dps.to_bits(),
            "sample {i}"
        );
        assert_eq!(axes[0].status[i], c.status);
    }
}

/// A log as named columns through the one entry: a single gyro's under the file's own names
/// and a unit's under its column names, each equal to what that form's reader gives (the
/// readers tested against the file's text in `csvlog.rs` and `imu_log.rs`).
#[test]
fn a_log_as_columns_holds_what_the_readers_read_under_the_file_s_names() {
    use gyrotherm::csvlog::{read_imu_log, read_log, read_log_columns, ColumnValues};
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.csv");
    std::fs::write(
        &one,
        "t,w,T,rt,note\n0,0.5,20,0,a\n1,0.25,20.5,0,b\n2,0.125,21,0,c\n",
    )
    .unwrap();
    let opts = ReadOptions {
        time_col: "t".into(),
        gyro_col: "w".into(),
        temp_col: "T".into(),
        table_col: "rt".into(),
        ..ReadOptions::default()
    };
    let (log, _) = read_log(&one, &opts).unwrap();
    let mut cols = read_log_columns(&one, &opts, None).unwrap();
    assert!(!cols.unit);
    let names: Vec<&str> = cols.columns.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["t", "w", "T", "rt", "note"]);
    assert_eq!(cols.sample_period_s, Some(1.0));
    assert_eq!(
        cols.columns[4].1,
        ColumnValues::Text(vec!["a".into(), "b".into(), "c".into()])
    );
    assert_eq!(cols.take_numbers("w").unwrap(), log.gyro_dps);
    assert_eq!(cols.take_numbers("T").unwrap(), log.temp_c);
    assert_eq!(Some(cols.take_numbers("rt").unwrap()), log.table_dps);
    assert!(cols.take_numbers("note").is_err());
    let missing = cols.take_numbers("gyro_dps").unwrap_err().to_string();
    assert!(
        missing.contains("available: t, w, T, rt, note"),
        "{missing}"
    );

    let unit = dir.path().join("unit.csv");
    std::fs::write(
        &unit,
        "time_s,gx,gy,t0,t1\n0,1,2,20,21\n0.5,1.5,2.5,20.5,21.5\n1,2,3,21,22\n",
    )
    .unwrap();
    let lists = ReadOptions {
        gyro_col: "gx,gy".into(),
        temp_col: "t0,t1".into(),
        ..ReadOptions::default()
    };
    let (u, _) = read_imu_log(&unit, &lists, None).unwrap();
    let mut cols = read_log_columns(&unit, &lists, None).unwrap();
    assert!(cols.unit);
    assert_eq!(
        (cols.gyro_cols.clone(), cols.temp_cols.clone()),
        (
            vec!["gx".to_owned(), "gy".into()],
            vec!["t0".to_owned(), "t1".into()]
        )
    );
    assert_eq!(cols.sample_period_s, Some(0.5));
    for s in u.gyro.iter().chain(&u.temp) {
        assert_eq!(cols.take_numbers(&s.name).unwrap(), s.values, "{}", s.name);
    }
}
