//! `langevin-fem scene show NAME|PATH`: a scene as it will run (TOML, every default filled
//! in), then every key it uses with its meaning, unit, allowed range and default
//! ([`langevin_fem::scene::keys`]). `langevin-fem scene keys`: the whole key table, as the
//! same TOML comments or as the Markdown page of the guide (`make docs` writes it to
//! `docs/src/reference/scene-keys.md`).

use clap::{Args, Subcommand};
use langevin_fem::error::Result;
use langevin_fem::scene::builtin::resolve;
use langevin_fem::scene::keys::{document, document_all, effective_toml, markdown, scene_keys};
use langevin_fem::scene::validate::Num;
use std::path::PathBuf;

/// Command-line arguments of `langevin-fem scene`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  langevin-fem scene show hinged-linear-2d                 as it will run, every key documented
  langevin-fem scene show hinged-linear-2d --as-written > my-scene.toml
  langevin-fem scene show my-scene.toml
  langevin-fem scene keys                                  every key, as TOML comments
  langevin-fem scene keys --format markdown                the guide's page of scene keys")]
pub struct SceneArgs {
    #[command(subcommand)]
    command: SceneCommand,
}

#[derive(Debug, Subcommand)]
enum SceneCommand {
    /// Print a scene as it will run (TOML, defaults filled in), then every key it uses
    /// with its meaning, unit, allowed range and default, as TOML comments.
    Show(ShowArgs),
    /// Print every scene key (the whole table, grouped by section) with its meaning,
    /// unit, allowed range and default: as TOML comments (as `show` writes them) or as
    /// Markdown (the guide's page docs/src/reference/scene-keys.md, written by `make docs`).
    Keys(KeysArgs),
}

/// Command-line arguments of `langevin-fem scene keys`.
#[derive(Debug, Args)]
struct KeysArgs {
    /// Output format: TOML comment lines, or a Markdown page with one table per section.
    #[arg(long, value_enum, default_value_t = KeysFormat::Toml)]
    format: KeysFormat,
}

/// The formats of `scene keys`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum KeysFormat {
    /// TOML comment lines, as `scene show` documents a scene's keys.
    Toml,
    /// A Markdown page: an intro on the units, then a table per section.
    Markdown,
}

/// Command-line arguments of `langevin-fem scene show`.
#[derive(Debug, Args)]
struct ShowArgs {
    /// The scene: a built-in scene's name (see `langevin-fem list`), a name in
    /// --scene-dir, or a path to a .toml file.
    #[arg(value_name = "NAME|PATH")]
    scene: String,
    /// Directory of scene files: the name resolves there instead of among the built-in
    /// scenes.
    #[arg(long, value_name = "DIR")]
    scene_dir: Option<PathBuf>,
    /// Print the scene file as written (with its comments) instead of the scene as it
    /// will run; the key documentation follows all the same.
    #[arg(long)]
    as_written: bool,
}

/// Runs `scene <command>`; exit code 0.
pub fn run(args: SceneArgs) -> Result<i32> {
    match args.command {
        SceneCommand::Show(args) => show(args),
        SceneCommand::Keys(args) => {
            print!(
                "{}",
                match args.format {
                    KeysFormat::Toml => document_all(),
                    KeysFormat::Markdown => markdown(),
                }
            );
            Ok(0)
        }
    }
}

/// Prints the scene and the documentation of its keys on stdout.
fn show(args: ShowArgs) -> Result<i32> {
    let source = resolve(&args.scene, args.scene_dir.as_deref())?;
    let scene = source.load()?;
    let label = source.label();
    let text = if args.as_written {
        format!("# {label}, as written\n{}", source.text()?)
    } else {
        let toml = effective_toml(&scene)?;
        format!(
            "# {label}, as it will run (every default filled in; the file with its comments: \
             langevin-fem scene show {} --as-written)\n{toml}",
            args.scene
        )
    };
    print!("{text}");
    if !text.ends_with('\n') {
        println!();
    }
    println!();
    if scene.is_membrane() {
        println!(
            "# Keys of {}: [unit] allowed range; default, then the meaning. Times in units of \
             tau1 = xi/(kappa q1^4 + sigma q1^2) = {} of the membrane's slowest mode where the \
             key ends in _tau1; [membrane] in the scene's own consistent units.",
            scene.name,
            Num(scene.tau1())
        );
    } else {
        println!(
            "# Keys of {}: [unit] allowed range; default, then the meaning. Times in units of \
             tau1 = xi L^4/(pi^4 EI) where the key ends in _tau1; [filament] in the scene's own \
             consistent units.",
            scene.name
        );
    }
    print!("{}", document(&scene_keys(&scene)?));
    Ok(0)
}
