//! Stage 2 of `oracle!`: builds an [`crate::Graph`] per oracle from the syntax tree (shared
//! sub-graphs spliced in), runs [`crate::validate()`] and turns each [`crate::GraphError`] back
//! into a `syn::Error` at the offending token. Checks that only the macro needs (missing `start`,
//! unknown `use`, parameter declarations) live here too.

use super::parse::{ArgDecl, Input, Item, NodeDecl, OracleDecl, ParamDecl, ParamValueDecl, SharedDecl, path_name};
use crate::model::{Arg, Arm, Graph, Node, Param, ParamType, ParamValue, Target, ToolRef};
use crate::validate::{Checked, Site, builtin_or_foreign, validate};
use std::borrow::Cow;

/// One oracle, ready to expand: its declaration, its nodes (own then spliced), and its graph.
pub struct OracleModel<'a> {
    /// The declaration.
    pub decl: &'a OracleDecl,
    /// Nodes in graph order (the graph's [`crate::NodeId`]s index this list).
    pub nodes: Vec<&'a NodeDecl>,
    /// The graph.
    pub graph: Graph,
    /// The validated graph; `None` when there were errors.
    pub checked: Option<Checked>,
}

/// Collects errors; each becomes a `compile_error!` at its span.
#[derive(Default)]
pub struct Errors(Option<syn::Error>);

impl Errors {
    /// Adds an error.
    pub fn push(&mut self, e: syn::Error) {
        match &mut self.0 {
            Some(all) => all.combine(e),
            None => self.0 = Some(e),
        }
    }

    /// The errors so far, if any.
    #[must_use]
    pub fn take(self) -> Option<syn::Error> {
        self.0
    }
}

/// Checks every oracle of the input.
pub fn check<'a>(input: &'a Input, errors: &mut Errors) -> Vec<OracleModel<'a>> {
    let shared: Vec<&SharedDecl> = input
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Shared(s) => Some(s),
            Item::Oracle(_) => None,
        })
        .collect();
    input
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Oracle(o) => Some(check_oracle(o, &shared, errors)),
            Item::Shared(_) => None,
        })
        .collect()
}

fn check_oracle<'a>(decl: &'a OracleDecl, shared: &[&'a SharedDecl], errors: &mut Errors) -> OracleModel<'a> {
    let mut local = Errors::default();
    let mut nodes: Vec<&NodeDecl> = decl.nodes.iter().collect();
    for u in &decl.uses {
        match shared.iter().find(|s| s.name == *u) {
            Some(s) => nodes.extend(s.nodes.iter()),
            None => local.push(syn::Error::new_spanned(u, format!("unknown shared sub-graph `{u}`"))),
        }
    }
    let start = match decl.starts.as_slice() {
        [] => {
            local.push(syn::Error::new_spanned(&decl.name, format!("oracle `{}` has no `start => node;`", decl.name)));
            // Validate the rest as if it started at the first node, without a wave of unreachable nodes.
            nodes.first().map_or(Target::Decision(crate::DecisionKind::Stop), |n| Target::parse(&n.name.to_string()))
        }
        [(_, first), rest @ ..] => {
            for (kw, _) in rest {
                local.push(syn::Error::new_spanned(kw, "duplicate `start`"));
            }
            Target::parse(&first.to_string())
        }
    };
    let params: Vec<Param> = decl.params.iter().filter_map(|p| check_param(p, &mut local)).collect();
    let graph = Graph {
        name: Cow::Owned(decl.name.to_string()),
        doc: Cow::Owned(doc_text(&decl.attrs)),
        params: Cow::Owned(params),
        start,
        nodes: Cow::Owned(nodes.iter().map(|n| node_of(n)).collect()),
    };
    let checked = match validate(&graph, &builtin_or_foreign) {
        Ok(c) => Some(c),
        Err(es) => {
            for e in es {
                local.push(syn::Error::new(site_span(decl, &nodes, e.site), e.message));
            }
            None
        }
    };
    let failed = local.0.is_some();
    if let Some(e) = local.take() {
        errors.push(e);
    }
    OracleModel { decl, nodes, graph, checked: if failed { None } else { checked } }
}

/// A parameter's type is `f64` or `u32`; its default lies in its range; a `u32` is whole.
fn check_param(p: &ParamDecl, errors: &mut Errors) -> Option<Param> {
    let Some(ty) = ParamType::from_rust_name(&p.ty.to_string()) else {
        errors.push(syn::Error::new_spanned(&p.ty, format!("unsupported parameter type `{}` (expected `f64` or `u32`)", p.ty)));
        return None;
    };
    let value = match &p.value {
        ParamValueDecl::Computed(c) => ParamValue::Computed { source: Cow::Owned(quote::quote!(#c).to_string()) },
        ParamValueDecl::Fixed { default, range } => {
            let (min, max) = match (range, ty) {
                (Some((lo, hi)), _) => (lo.value, hi.value),
                (None, ParamType::F64) => (f64::NEG_INFINITY, f64::INFINITY),
                (None, ParamType::U32) => (0.0, f64::from(u32::MAX)),
            };
            ParamValue::Fixed { default: default.value, min, max }
        }
    };
    let param = Param { name: Cow::Owned(p.name.to_string()), ty, value };
    if let (ParamValueDecl::Fixed { default, .. }, ParamValue::Fixed { default: d, .. }) = (&p.value, &param.value)
        && let Err(msg) = param.check(*d)
    {
        // Kept in the graph so its uses are not reported as unknown too.
        errors.push(syn::Error::new_spanned(&default.tokens, format!("default of {msg}")));
    }
    Some(param)
}

fn node_of(n: &NodeDecl) -> Node {
    let args = n
        .args
        .iter()
        .map(|a| match a {
            ArgDecl::Param(i) => Arg::Param(Cow::Owned(i.to_string())),
            ArgDecl::Number(x) => Arg::Number(x.value),
        })
        .collect::<Vec<_>>();
    let arms = n
        .arms
        .iter()
        .map(|a| Arm {
            answers: Cow::Owned(a.answers.iter().map(|x| Cow::Owned(x.to_string())).collect()),
            target: Target::parse(&a.target.to_string()),
        })
        .collect::<Vec<_>>();
    Node {
        name: Cow::Owned(n.name.to_string()),
        tool: ToolRef { name: Cow::Owned(path_name(&n.tool)), args: Cow::Owned(args) },
        arms: Cow::Owned(arms),
    }
}

fn site_span(decl: &OracleDecl, nodes: &[&NodeDecl], site: Site) -> proc_macro2::Span {
    use syn::spanned::Spanned;
    match site {
        Site::Start => decl.starts.first().map_or(decl.name.span(), |(_, t)| t.span()),
        Site::Param(i) => decl.params.get(i).map_or(decl.name.span(), |p| p.name.span()),
        Site::Node(id) => nodes[id.index()].name.span(),
        Site::Tool(id) => nodes[id.index()].tool.span(),
        Site::Arg(id, k) => nodes[id.index()].args[k].span(),
        Site::Answer(id, a, k) => nodes[id.index()].arms[a].answers[k].span(),
        Site::ArmTarget(id, a) => nodes[id.index()].arms[a].target.span(),
    }
}

/// The doc comment of an item as one paragraph.
#[must_use]
pub fn doc_text(attrs: &[syn::Attribute]) -> String {
    let mut lines = Vec::new();
    for a in attrs {
        if let syn::Meta::NameValue(nv) = &a.meta
            && nv.path.is_ident("doc")
            && let syn::Expr::Lit(syn::ExprLit { lit: syn::Lit::Str(s), .. }) = &nv.value
        {
            lines.push(s.value().trim().to_owned());
        }
    }
    lines.join(" ").trim().to_owned()
}
