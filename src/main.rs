use clap::Parser;

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).format_timestamp(None).init();
    let cli = match translucent::cli::Cli::try_parse() {
        Ok(cli) => cli,
        // clap prints `error: …` and exits 2 on usage errors, 0 for --help / --version.
        Err(e) => e.exit(),
    };
    let code = match translucent::cli::run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    };
    std::process::exit(code);
}
