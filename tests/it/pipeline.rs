//! The library's whole runs (`fitbead::pipeline`) against the command line: the same bytes
//! for the same settings, and settings errors named by the command line's flags.

use crate::common::{bin, root, stdout_ok, tmpdir, write};
use fitbead::io::measurements::{MeasurementDefaults, MeasurementFile};
use fitbead::models::{JaegerBranch, ModelKind};
use fitbead::pipeline::{ReportSettings, RunError, SimulateSettings};

#[test]
fn simulate_from_the_library_is_the_commands_output() {
    let out = bin()
        .args([
            "simulate", "--model", "jaeger", "--series", "1,2", "--points", "4",
        ])
        .args(["--seed", "5", "--noise", "0.03", "--branch", "lower"])
        .output()
        .unwrap();
    let cli = stdout_ok(&out);
    let lib = (SimulateSettings {
        model: ModelKind::Jaeger,
        series: vec![1.0, 2.0],
        points: 4,
        seed: 5,
        noise: 0.03,
        branch: JaegerBranch::Lower,
        ..SimulateSettings::default()
    })
    .run()
    .unwrap();
    assert_eq!(String::from_utf8(lib).unwrap(), cli);
}

#[test]
fn simulate_from_a_design_in_the_library_is_the_commands_output() {
    let dir = tmpdir();
    let design = write(
        &dir,
        "design.csv",
        "series,xi,delta_deg,replicates\nA,1,10,2\nB,2,5,1\n",
    );
    let out = bin()
        .args(["simulate", "--model", "stick", "--seed", "3", "--design"])
        .arg(&design)
        .output()
        .unwrap();
    let lib = (SimulateSettings {
        model: ModelKind::Stick,
        seed: 3,
        design: Some(design),
        ..SimulateSettings::default()
    })
    .run()
    .unwrap();
    assert_eq!(String::from_utf8(lib).unwrap(), stdout_ok(&out));
}

#[test]
fn a_bad_simulate_setting_is_named_by_its_flag() {
    let e = (SimulateSettings {
        points: 0,
        ..SimulateSettings::default()
    })
    .run()
    .unwrap_err();
    let RunError::Input(ie) = &e else {
        panic!("expected an input error, got {e}")
    };
    assert_eq!(ie.column.as_deref(), Some("--points"));
    assert_eq!(ie.value.as_deref(), Some("0"));
    let e = (SimulateSettings {
        series: vec![1.0, 2.0, 1.0],
        ..SimulateSettings::default()
    })
    .run()
    .unwrap_err();
    assert!(e.to_string().contains("xi 1 is given twice"), "{e}");
}

#[test]
fn report_from_the_library_writes_the_commands_directory() {
    let dir = tmpdir();
    let (cli_dir, lib_dir) = (dir.path().join("cli"), dir.path().join("lib"));
    let data = root().join("data").join("default.csv");
    let out = bin()
        .args(["report", "--input"])
        .arg(&data)
        .arg("--out-dir")
        .arg(&cli_dir)
        .output()
        .unwrap();
    let summary = stdout_ok(&out);
    let file = MeasurementFile::read(&data, &MeasurementDefaults::default()).unwrap();
    let rep = ReportSettings::default()
        .run(&file, Some(lib_dir.as_path()))
        .unwrap();
    assert_eq!(
        rep.summary.replace(&lib_dir.display().to_string(), "DIR"),
        summary.replace(&cli_dir.display().to_string(), "DIR")
    );
    let mut names: Vec<String> = std::fs::read_dir(&cli_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with('.'))
        .collect();
    names.sort();
    let mut returned: Vec<String> = rep.files.iter().map(|(n, _)| n.clone()).collect();
    returned.sort();
    assert_eq!(returned, names);
    for (name, bytes) in &rep.files {
        let cli = std::fs::read(cli_dir.join(name)).unwrap();
        assert!(cli == *bytes, "{name} differs from the command line's");
        assert!(
            std::fs::read(lib_dir.join(name)).unwrap() == cli,
            "{name} written differs"
        );
    }
    assert!(!rep.interrupted);
}

#[test]
fn a_bad_report_setting_is_named_by_its_flag_and_writes_nothing() {
    let dir = tmpdir();
    let data = root().join("data").join("default.csv");
    let file = MeasurementFile::read(&data, &MeasurementDefaults::default()).unwrap();
    let e = (ReportSettings {
        format: "gif".into(),
        ..ReportSettings::default()
    })
    .run(&file, Some(dir.path().join("never").as_path()))
    .unwrap_err();
    let RunError::Input(ie) = &e else {
        panic!("expected an input error, got {e}")
    };
    assert_eq!(ie.column.as_deref(), Some("--format"));
    assert!(!dir.path().join("never").exists());
}
