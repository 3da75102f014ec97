// TEMPORARY (deleted before hand-off): compiles cli/truth.rs standalone to test it.
#[path = "../src/cli/parse.rs"]
#[allow(dead_code)]
mod parse;
#[path = "../src/cli/truth.rs"]
mod truth;
pub fn emit(s: &str) {
    use std::io::Write;
    let _ = std::io::stdout().lock().write_all(s.as_bytes());
}
use clap::Parser;
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    a: truth::TruthArgs,
}
fn main() {
    let c = Cli::parse();
    if let Err(e) = truth::run(&c.a) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
