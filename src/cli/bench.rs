//! `whitted bench`: the study of run time against error (see `whitted::bench`).

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::Args;

use whitted::bench::{self, BenchOptions};

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// Folder for the outputs (and a cache of the slow reference images).
    #[arg(long, value_name = "DIR", default_value = "bench-out")]
    out: PathBuf,
    /// Image size of every render.
    #[arg(long, value_name = "WxH", default_value = "320x180", value_parser = bench::parse_size)]
    size: (u32, u32),
    /// Timed runs per setting, at least (the median is reported; settings that take
    /// milliseconds get up to 10 times as many).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    runs: u32,
    /// A tiny grid on small scenes, for a quick check.
    #[arg(long)]
    tiny: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// No progress bar and no summary.
    #[arg(short, long)]
    quiet: bool,
    /// Measure nothing: draw bench.svg in the output folder again from its bench.csv.
    #[arg(long)]
    replot: bool,
}

pub(crate) fn bench_command(args: BenchArgs) -> anyhow::Result<()> {
    if args.replot {
        return bench::replot(&args.out);
    }
    let opts = BenchOptions {
        out: args.out,
        width: args.size.0,
        height: args.size.1,
        runs: args.runs as usize,
        tiny: args.tiny,
        threads: args.threads.map(|t| t as usize),
        progress: !args.quiet && std::io::stderr().is_terminal(),
    };
    let rows = bench::run(&opts)?;
    if !args.quiet {
        eprint!("{}", bench::summary(&rows, &opts.out));
    }
    Ok(())
}
