//! `radiosity oracle {list,dot,explain,study}`: the named refinement oracles, their decision graphs,
//! and the visibility study behind their visibility nodes.

use super::{CommonOptions, load_scene};
use radiosity::oracle::{self, registry};
use std::path::PathBuf;

/// Oracle subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum OracleCommand {
    /// The built-in oracles, their release (hand, flat, dag) and parameters.
    List,
    /// The decision graph of an oracle (a name or a `*.toml` graph file) in Graphviz DOT.
    Dot {
        /// Oracle name or graph file.
        name: String,
    },
    /// The execution track of one emitter/receiver pair: each node, its answer and the values it
    /// used (element ids as in the hierarchy: input polygon i is element i).
    Explain {
        /// Oracle name or graph file.
        name: String,
        /// Emitter element id.
        #[arg(long)]
        emitter: u32,
        /// Receiver element id.
        #[arg(long)]
        receiver: u32,
        /// Scene (the Cornell box when omitted).
        scene: Option<PathBuf>,
        /// Oracle parameters, `name=value`.
        #[arg(long = "param", value_name = "NAME=VALUE")]
        params: Vec<String>,
        #[command(flatten)]
        options: CommonOptions,
    },
    /// The visibility study: for the links of a BF solve whose projected areas lie below each
    /// threshold, the share that 4, 16 and 64 rays classify differently from the reference.
    Study(super::study::StudyArgs),
}

/// Parses `--param name=value` arguments.
pub fn parse_params(params: &[String]) -> anyhow::Result<Vec<(String, f64)>> {
    params.iter().map(|p| Ok(oracle::parse_param_assignment(p)?)).collect()
}

/// Runs an oracle subcommand.
pub fn run(cmd: OracleCommand) -> anyhow::Result<()> {
    match cmd {
        OracleCommand::List => {
            for info in registry::ORACLES {
                println!("{:<10} {:<5} {}", info.name, info.release, info.doc);
                println!("{:<16} params: {}", "", registry::params(info.name)?);
            }
            println!("(any graph file `*.toml` is an oracle too; see `radiosity oracle dot bf-dag`)");
            Ok(())
        }
        OracleCommand::Dot { name } => {
            print!("{}", oracle::graph::to_dot(&registry::graph(&name)?, None));
            Ok(())
        }
        OracleCommand::Explain { name, emitter, receiver, scene, params, options } => {
            options.validate()?;
            let scene = load_scene(scene.as_ref(), options.allow_dark)?;
            let params = parse_params(&params)?;
            let (graph, trace) = radiosity::lab::explain(&name, &params, &scene, &options.config(), emitter, receiver)?;
            if trace.is_empty() {
                println!("the pair {emitter} -> {receiver} was never asked (not a candidate link of this solve)");
            } else {
                print!("{}", oracle::runtime::format_trace(&graph, &trace));
            }
            Ok(())
        }
        OracleCommand::Study(args) => super::study::run(&args),
    }
}
