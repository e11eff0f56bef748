//! The oracles a front end can name (`radiosity solve --oracle NAME`, `radiosity oracle list`):
//! the BF oracle in its three releases, and any graph file (a path ending in `.toml`).

use super::bf::{BF_TOML, BfFlat, BfFlatParams};
use super::runtime::{DagOracle, load_graph, parse_graph};
use super::{NoProbe, ParamError, check_param, param_list};
use crate::refine::{BfHand, BfParams, Oracle};
use oracle_graph::Graph;
use std::path::Path;

/// A named oracle: its name, its release, and one line about it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OracleInfo {
    /// Name on the command line.
    pub name: &'static str,
    /// `hand`, `flat` (`oracle!`) or `dag` (runtime).
    pub release: &'static str,
    /// One line.
    pub doc: &'static str,
}

/// The built-in named oracles.
pub const ORACLES: &[OracleInfo] = &[
    OracleInfo { name: "bf", release: "flat", doc: "classic BF refiner compiled by `oracle!`" },
    OracleInfo { name: "bf-dag", release: "dag", doc: "classic BF refiner interpreted by the DAG runtime" },
    OracleInfo { name: "bf-hand", release: "hand", doc: "classic BF refiner written by hand (the baseline)" },
    OracleInfo {
        name: "shaft",
        release: "flat",
        doc: "shaft oracle compiled by `oracle!` (its tools need shafts: OBB culling unless another volume is chosen)",
    },
];

/// Why a name did not give an oracle.
#[derive(Debug, thiserror::Error)]
pub enum RegistryError {
    /// Neither a built-in name nor a graph file.
    #[error("unknown oracle `{0}` (oracles: bf, bf-dag, bf-hand, shaft, or a graph file `*.toml`)")]
    Unknown(String),
    /// A parameter was rejected.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The graph file was rejected.
    #[error(transparent)]
    File(#[from] super::runtime::GraphFileError),
    /// The graph could not be compiled.
    #[error(transparent)]
    Runtime(#[from] super::runtime::RuntimeError),
}

/// The decision graph of oracle `name` (a built-in name or a graph file path).
pub fn graph(name: &str) -> Result<Graph, RegistryError> {
    match name {
        "bf" | "bf-hand" => Ok(BfFlat::<NoProbe>::GRAPH),
        "bf-dag" => Ok(parse_graph(BF_TOML, Path::new("<bf>"))?),
        "shaft" => Ok(super::shaft::ShaftOracle::<NoProbe>::GRAPH),
        path if path.ends_with(".toml") => Ok(load_graph(Path::new(path))?),
        other => Err(RegistryError::Unknown(other.to_owned())),
    }
}

/// The parameters of oracle `name` as `name: type = default in [min, max]`, comma-separated.
pub fn params(name: &str) -> Result<String, RegistryError> {
    Ok(param_list(&graph(name)?))
}

/// Oracle `name` with parameters `params` (`(name, value)`, checked against the declared ranges).
pub fn oracle(name: &str, params: &[(String, f64)]) -> Result<Box<dyn Oracle>, RegistryError> {
    let g = graph(name)?;
    for (p, v) in params {
        check_param(&g, p, *v)?;
    }
    match name {
        "bf" => {
            let mut p = BfFlatParams::default();
            for (n, v) in params {
                p.set(n, *v)?;
            }
            Ok(Box::new(BfFlat::new(p)))
        }
        "bf-hand" => {
            let mut p = BfParams::default();
            for (n, v) in params {
                match n.as_str() {
                    "eps" => p.eps = *v,
                    // The hand-written oracle has no `min_area`: only the default (0) is accepted.
                    _ if *v == 0.0 => {}
                    _ => return Err(ParamError { message: format!("parameter `{n}` is not supported by `bf-hand`") }.into()),
                }
            }
            Ok(Box::new(BfHand { params: p }))
        }
        "shaft" => {
            let mut p = super::shaft::ShaftOracleParams::default();
            for (n, v) in params {
                p.set(n, *v)?;
            }
            Ok(Box::new(super::shaft::ShaftOracle::new(p)))
        }
        _ => Ok(Box::new(DagOracle::new(g, params)?)),
    }
}
