use clap::Parser;

fn main() {
    let cli = granflow::cli::Cli::parse();
    match granflow::cli::run(cli) {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(e.exit_code());
        }
    }
}
