//! The binary's commands as its help lists them. The library's integration tests
//! (`tests/it` at the workspace root) run this package's binary through every command; this
//! test also makes `cargo test` build the binary they run.

use std::process::Command;

/// Every subcommand, in the order of the help.
const COMMANDS: [&str; 10] = [
    "forward", "k", "klaw", "jan", "jaeger", "regimes", "report", "simulate", "design", "bench",
];

#[test]
fn the_help_lists_every_command_and_the_version_is_the_packages() {
    let out = Command::new(env!("CARGO_BIN_EXE_fitbead"))
        .arg("--help")
        .output()
        .unwrap();
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    let listed: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert_eq!(listed, COMMANDS, "{help}");
    let out = Command::new(env!("CARGO_BIN_EXE_fitbead"))
        .arg("--version")
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8(out.stdout).unwrap(),
        format!("fitbead {}\n", env!("CARGO_PKG_VERSION"))
    );
}
