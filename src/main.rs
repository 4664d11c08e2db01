use clap::Parser;

fn main() {
    let cli = granflow::cli::Cli::parse();
    if let Err(e) = granflow::cli::run(cli) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
