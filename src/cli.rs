//! The `unfold` command line: parse options (the schemes' own from the registry),
//! merge the configuration file, call the library, print the report, turn the result
//! into an exit code. Nothing else. The binary runs it with the built-in schemes; a
//! program embedding the library can run it with more.

use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use crate::config::{load_config, BuildOptions, ModelOptions, NonPlanar};
use crate::scheme::Registry;
use crate::{Error, Result};

/// Turn a 3D polygon mesh into developable flat panels laid out on laser-cutter sheets.
///
/// Exit codes: 0 success, 1 runtime failure, 2 usage error, 3 bad input model.
#[derive(Debug, Parser)]
#[command(
    name = "unfold",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    args_override_self = true,
    after_help = "Lengths take a unit: mm, cm, m, in, ft (4ft, 0.25in, 600mm).\n\
                  Examples:\n  unfold inspect models/genus2.obj\n  \
                  unfold bunny.obj --scheme quad-edge --sheet 18x24in --size 4ft --out build/bunny"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    /// The model to build: .obj, .off or .stl.
    #[arg(value_name = "MODEL", required = true)]
    model: Option<PathBuf>,

    /// Read options from a TOML file (keys are the long option names, e.g.
    /// sheet = "18x24in"); options on the command line win.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,

    #[command(flatten)]
    build: BuildOptions,
}

#[derive(Debug, Subcommand)]
enum Command {
    #[command(args_override_self = true)]
    /// Print a model's topology and geometry (V, E, F, face sizes, boundary loops,
    /// components, genus, size, planarity) and every repair the tool would make.
    Inspect {
        /// The model: .obj, .off or .stl.
        #[arg(value_name = "MODEL")]
        model: PathBuf,

        /// Print the facts as JSON on stdout instead of text.
        #[arg(long)]
        json: bool,

        /// Read options from a TOML file (a build's config file: its model options and
        /// non-planar policy are used, its other keys ignored); options on the command
        /// line win.
        #[arg(long, value_name = "FILE")]
        config: Option<PathBuf>,

        /// Preview this non-planar face policy: triangulate, planarize (runs the
        /// planarization and reports the errors before and after and the largest vertex
        /// move) or error.
        #[arg(long, value_name = "POLICY")]
        nonplanar: Option<NonPlanar>,

        #[command(flatten)]
        options: ModelOptions,
    },
}

/// Runs the command line `args` (the program name first) with the schemes of
/// `registry`, printing to stdout and stderr, and returns the exit code.
pub fn main(registry: &Registry, args: impl IntoIterator<Item = OsString>) -> ExitCode {
    let args: Vec<OsString> = args.into_iter().collect();
    let command = BuildOptions::with_registry(Cli::command(), registry);
    let parsed = command.try_get_matches_from(&args).and_then(|matches| {
        let mut cli = Cli::from_arg_matches(&matches)?;
        cli.build.scheme_values = BuildOptions::scheme_values(&matches, registry);
        Ok(cli)
    });
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => match spaced_length(&args) {
            Some(hint) => {
                eprintln!("unfold: error: {hint}");
                return ExitCode::from(2);
            }
            None => return usage_error(e),
        },
    };
    match crate::internal::catch(|| run(cli, registry)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The whole chain of causes, each once: a message that already quotes
            // its cause (an I/O error's reason) does not repeat it.
            let mut shown = e.to_string();
            eprintln!("unfold: error: {shown}");
            let mut source = std::error::Error::source(&e);
            while let Some(cause) = source {
                let text = cause.to_string();
                if !shown.contains(&text) {
                    eprintln!("  caused by: {text}");
                    shown = text;
                }
                source = cause.source();
            }
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// An option's length written with a space before its unit (`--size 4 ft`), which the
/// shell splits in two: the message a user needs instead of clap's about a stray
/// argument.
fn spaced_length(args: &[OsString]) -> Option<String> {
    args.windows(3).find_map(|w| {
        let (option, number, unit) = (w[0].to_str()?, w[1].to_str()?, w[2].to_str()?);
        let spaced = option.starts_with("--")
            && number.parse::<f64>().is_ok()
            && crate::units::LengthUnit::parse_suffix(unit).is_some();
        spaced.then(|| {
            format!(
                "{option} {number} {unit}: write a length without a space before its unit: {option} {number}{unit}"
            )
        })
    })
}

/// Help and version go to stdout as clap renders them. Any other parse error keeps
/// clap's whole message (the tip of a similar option, the values an option takes, the
/// missing argument, the usage line), prefixed like every other error of the tool, with
/// exit code 2.
fn usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    let rendered = e.to_string();
    let message = rendered.trim_end().trim_start_matches("error: ");
    eprintln!("unfold: error: {message}");
    ExitCode::from(2)
}

fn run(cli: Cli, registry: &Registry) -> Result<()> {
    match cli.command {
        Some(Command::Inspect {
            model,
            json,
            config,
            nonplanar,
            options,
        }) => {
            // The build's own config file works here: its model options and non-planar
            // policy are what preparation uses; its other keys (sheet, scheme, ...) do
            // not change preparation and are read but not used.
            let (options, nonplanar) = match config {
                Some(path) => {
                    let file = load_config(&path, registry)?;
                    (options.or(file.model), nonplanar.or(file.nonplanar))
                }
                None => (options, nonplanar),
            };
            let settings = options.resolve()?;
            if settings.auto_budget {
                return Err(Error::Usage(
                    "--target-edges auto: the budget is found by a build (it depends on the scheme, the sheet and the size); give inspect a number of edges".to_string(),
                ));
            }
            let nonplanar = nonplanar.unwrap_or(crate::config::defaults::NONPLANAR);
            let report = crate::inspect(&model, &settings, nonplanar, registry)?;
            let text = if json {
                serde_json::to_string_pretty(&report)
                    .map_err(|e| Error::internal("writing the JSON summary", e))?
                    + "\n"
            } else {
                report.to_text()
            };
            // A closed pipe (`| head`) is not an error worth a panic.
            let _ = std::io::stdout().lock().write_all(text.as_bytes());
            Ok(())
        }
        None => {
            let model = cli
                .model
                .ok_or_else(|| Error::Usage("give a model file".to_string()))?;
            let options = match cli.config {
                Some(path) => cli.build.or(load_config(&path, registry)?),
                None => cli.build,
            };
            let job = options.resolve_with(&model, registry)?;
            let quiet = job.quiet;
            let outcome = crate::run_observed(&job, &mut |warning| {
                if !quiet {
                    eprintln!("unfold: warning: {warning}");
                }
            })?;
            if !job.quiet {
                eprint!("{}", crate::report_text(&outcome, &job.out));
            }
            if job.json {
                let mut summary = serde_json::to_value(&outcome.manifest)
                    .map_err(|e| Error::internal("writing the JSON summary", e))?;
                if let Some(map) = summary.as_object_mut() {
                    map.remove("panels");
                    let times: serde_json::Map<String, serde_json::Value> = outcome
                        .times
                        .iter()
                        .map(|(stage, t)| (format!("{stage}_ms"), (t.as_secs_f64() * 1e3).into()))
                        .collect();
                    map.insert("times".into(), times.into());
                }
                let text = serde_json::to_string_pretty(&summary)
                    .map_err(|e| Error::internal("writing the JSON summary", e))?;
                let _ = writeln!(std::io::stdout().lock(), "{text}");
            }
            Ok(())
        }
    }
}
