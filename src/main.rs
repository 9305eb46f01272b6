use clap::Parser;

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).format_timestamp(None).init();
    let cli = match translucent::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => std::process::exit(translucent::cli::usage_exit(e)),
    };
    let code = match translucent::commands::run(cli) {
        Ok(code) => code,
        Err(e) => {
            translucent::note!("error: {e}");
            e.exit_code()
        }
    };
    std::process::exit(code);
}
