//! Stage 1 of `oracle!`: the syntax tree, parsed with syn. Every node keeps the user's tokens so
//! later stages can place errors on them.
//!
//! ```text
//! input   := ("crate" "=" path ";")? item*
//! item    := attr* vis "oracle" ident "{" body "}" | attr* "shared" ident "{" node* "}"
//! body    := ("params" "{" param,* "}" | "use" ident ";" | "start" "=>" ident ";" | node)*
//! param   := ident ":" type "=" number ("in" number "..=" number)? | ident ":" type "=" "computed" closure
//! node    := ident ":" path ("(" arg,* ")")? "{" (ident ("|" ident)* "=>" ident),* "}"
//! ```

use proc_macro2::{Delimiter, Span, TokenStream, TokenTree};
use quote::ToTokens;
use syn::parse::{Parse, ParseStream, Parser};
use syn::punctuated::Punctuated;
use syn::{Attribute, ExprClosure, Ident, Path, Token, Visibility, braced, parenthesized};

mod kw {
    syn::custom_keyword!(oracle);
    syn::custom_keyword!(shared);
    syn::custom_keyword!(params);
    syn::custom_keyword!(start);
    syn::custom_keyword!(computed);
}

/// The whole macro input.
pub struct Input {
    /// `crate = path;`: where `radiosity_core` is (default `::radiosity_core`).
    pub krate: Option<Path>,
    /// Oracles and shared sub-graphs, in order.
    pub items: Vec<Item>,
}

/// One top-level item.
pub enum Item {
    /// An oracle.
    Oracle(OracleDecl),
    /// A shared sub-graph.
    Shared(SharedDecl),
}

/// `pub oracle Name { ... }`.
pub struct OracleDecl {
    /// Attributes (doc comments are kept for the generated type).
    pub attrs: Vec<Attribute>,
    /// Visibility of the generated types.
    pub vis: Visibility,
    /// The `oracle` keyword.
    pub keyword: kw::oracle,
    /// The oracle's name.
    pub name: Ident,
    /// Declared parameters.
    pub params: Vec<ParamDecl>,
    /// `use shared;` items, spliced in order.
    pub uses: Vec<Ident>,
    /// `start => node;` items (more than one is an error).
    pub starts: Vec<(kw::start, Ident)>,
    /// Nodes in order.
    pub nodes: Vec<NodeDecl>,
}

/// `shared name { nodes }`: nodes several oracles may `use`.
pub struct SharedDecl {
    /// Attributes.
    pub attrs: Vec<Attribute>,
    /// Name.
    pub name: Ident,
    /// Nodes in order.
    pub nodes: Vec<NodeDecl>,
}

/// One parameter.
pub struct ParamDecl {
    /// Name.
    pub name: Ident,
    /// Type word (`f64`, `u32`).
    pub ty: Ident,
    /// Fixed or computed.
    pub value: ParamValueDecl,
}

/// A parameter's value.
pub enum ParamValueDecl {
    /// `= default (in min..=max)?`.
    Fixed {
        /// Default value and its tokens.
        default: Number,
        /// Inclusive range.
        range: Option<(Number, Number)>,
    },
    /// `= computed |ctx| expr`.
    Computed(Box<ExprClosure>),
}

/// A number written in the input, with its tokens (sign included).
#[derive(Clone)]
pub struct Number {
    /// Its value.
    pub value: f64,
    /// Whether it was written as an integer.
    pub is_int: bool,
    /// The tokens, for spans and for re-emitting.
    pub tokens: TokenStream,
}

/// One node.
pub struct NodeDecl {
    /// Name.
    pub name: Ident,
    /// The tool.
    pub tool: Path,
    /// Arguments.
    pub args: Vec<ArgDecl>,
    /// Arms in order.
    pub arms: Vec<ArmDecl>,
}

/// One tool argument.
pub enum ArgDecl {
    /// A parameter name.
    Param(Ident),
    /// A number.
    Number(Number),
}

/// One arm: `A | B => target`.
pub struct ArmDecl {
    /// The answers matched.
    pub answers: Vec<Ident>,
    /// The next node or decision word.
    pub target: Ident,
}

impl Parse for Input {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let mut krate = None;
        if input.peek(Token![crate]) && input.peek2(Token![=]) {
            input.parse::<Token![crate]>()?;
            input.parse::<Token![=]>()?;
            krate = Some(Path::parse_mod_style(input)?);
            input.parse::<Token![;]>()?;
        }
        let mut items = Vec::new();
        while !input.is_empty() {
            items.push(input.parse()?);
        }
        Ok(Input { krate, items })
    }
}

impl Parse for Item {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let attrs = input.call(Attribute::parse_outer)?;
        if input.peek(kw::shared) {
            input.parse::<kw::shared>()?;
            let name: Ident = input.parse()?;
            let content;
            braced!(content in input);
            let mut nodes = Vec::new();
            while !content.is_empty() {
                nodes.push(content.parse()?);
            }
            return Ok(Item::Shared(SharedDecl { attrs, name, nodes }));
        }
        let vis: Visibility = input.parse()?;
        let lookahead = input.lookahead1();
        if !lookahead.peek(kw::oracle) {
            if matches!(vis, Visibility::Inherited) && !lookahead.peek(kw::shared) {
                let mut e = lookahead.error();
                e.combine(syn::Error::new(input.span(), "expected one of: `oracle`, `shared`"));
                return Err(e);
            }
            return Err(lookahead.error());
        }
        let keyword: kw::oracle = input.parse()?;
        let name: Ident = input.parse()?;
        let content;
        braced!(content in input);
        let mut decl =
            OracleDecl { attrs, vis, keyword, name, params: Vec::new(), uses: Vec::new(), starts: Vec::new(), nodes: Vec::new() };
        while !content.is_empty() {
            if content.peek(kw::params) && content.peek2(syn::token::Brace) {
                content.parse::<kw::params>()?;
                let body;
                braced!(body in content);
                let list = Punctuated::<ParamDecl, Token![,]>::parse_terminated(&body)?;
                decl.params.extend(list);
            } else if content.peek(Token![use]) {
                content.parse::<Token![use]>()?;
                decl.uses.push(content.parse()?);
                content.parse::<Token![;]>()?;
            } else if content.peek(kw::start) && content.peek2(Token![=>]) {
                let kw: kw::start = content.parse()?;
                content.parse::<Token![=>]>()?;
                let target: Ident = content.parse()?;
                content.parse::<Token![;]>()?;
                decl.starts.push((kw, target));
            } else {
                decl.nodes.push(content.parse()?);
            }
        }
        Ok(Item::Oracle(decl))
    }
}

impl Parse for ParamDecl {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let name: Ident = input.parse()?;
        input.parse::<Token![:]>()?;
        let ty: Ident = input.parse()?;
        input.parse::<Token![=]>()?;
        if input.peek(kw::computed) {
            input.parse::<kw::computed>()?;
            let closure: ExprClosure = input.parse()?;
            return Ok(ParamDecl { name, ty, value: ParamValueDecl::Computed(Box::new(closure)) });
        }
        let default: Number = input.parse()?;
        let mut range = None;
        if input.peek(Token![in]) {
            input.parse::<Token![in]>()?;
            let lo: Number = input.parse()?;
            if input.peek(Token![..=]) {
                input.parse::<Token![..=]>()?;
            } else {
                let dots: Token![..] = input.parse()?;
                return Err(syn::Error::new_spanned(dots, "expected an inclusive range `min..=max`"));
            }
            let hi: Number = input.parse()?;
            range = Some((lo, hi));
        }
        Ok(ParamDecl { name, ty, value: ParamValueDecl::Fixed { default, range } })
    }
}

impl Parse for Number {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let mut tokens = TokenStream::new();
        let neg = if input.peek(Token![-]) {
            let minus: Token![-] = input.parse()?;
            minus.to_tokens(&mut tokens);
            true
        } else {
            false
        };
        let lookahead = input.lookahead1();
        let (value, is_int) = if lookahead.peek(syn::LitFloat) {
            let lit: syn::LitFloat = input.parse()?;
            lit.to_tokens(&mut tokens);
            (lit.base10_parse::<f64>()?, false)
        } else if lookahead.peek(syn::LitInt) {
            let lit: syn::LitInt = input.parse()?;
            lit.to_tokens(&mut tokens);
            (lit.base10_parse::<f64>()?, true)
        } else {
            return Err(lookahead.error());
        };
        Ok(Number { value: if neg { -value } else { value }, is_int, tokens })
    }
}

impl Parse for NodeDecl {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let name: Ident = input.parse()?;
        input.parse::<Token![:]>()?;
        let tool = Path::parse_mod_style(input)?;
        let mut args = Vec::new();
        if input.peek(syn::token::Paren) {
            let content;
            parenthesized!(content in input);
            let list = Punctuated::<ArgDecl, Token![,]>::parse_terminated(&content)?;
            args.extend(list);
        }
        let content;
        braced!(content in input);
        let arms = Punctuated::<ArmDecl, Token![,]>::parse_terminated(&content)?;
        Ok(NodeDecl { name, tool, args, arms: arms.into_iter().collect() })
    }
}

impl Parse for ArgDecl {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        if input.peek(Ident) { Ok(ArgDecl::Param(input.parse()?)) } else { Ok(ArgDecl::Number(input.parse()?)) }
    }
}

impl Parse for ArmDecl {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let mut answers = vec![input.parse::<Ident>()?];
        while input.peek(Token![|]) {
            input.parse::<Token![|]>()?;
            answers.push(input.parse()?);
        }
        input.parse::<Token![=>]>()?;
        let target: Ident = input.parse()?;
        Ok(ArmDecl { answers, target })
    }
}

impl ArgDecl {
    /// Span of the argument, for messages.
    #[must_use]
    pub fn span(&self) -> Span {
        match self {
            ArgDecl::Param(i) => i.span(),
            ArgDecl::Number(n) => n.tokens.clone().into_iter().next().map_or_else(Span::call_site, |t| t.span()),
        }
    }
}

/// The tool's name as written, without spaces (`Facing`, `my::Tool`).
#[must_use]
pub fn path_name(path: &Path) -> String {
    path.to_token_stream().to_string().replace(' ', "")
}

/// What can be recovered from input that does not parse: the `crate = path;` prefix and each
/// top-level `vis oracle Name { ... }` with its parameters (when its `params { ... }` block
/// parses) and no nodes. The macro emits the fallback of each next to the syntax error, so that
/// error is the only one the user sees.
#[must_use]
pub fn recover(input: TokenStream) -> Input {
    let krate = (|s: ParseStream<'_>| {
        let krate = if s.peek(Token![crate]) && s.peek2(Token![=]) {
            s.parse::<Token![crate]>()?;
            s.parse::<Token![=]>()?;
            let path = Path::parse_mod_style(s)?;
            s.parse::<Token![;]>()?;
            Some(path)
        } else {
            None
        };
        s.parse::<TokenStream>()?;
        Ok(krate)
    })
    .parse2(input.clone())
    .ok()
    .flatten();
    let tokens: Vec<TokenTree> = input.into_iter().collect();
    let is_word = |t: &TokenTree, word: &str| matches!(t, TokenTree::Ident(i) if i == word);
    let mut items = Vec::new();
    for (i, window) in tokens.windows(3).enumerate() {
        let [TokenTree::Ident(keyword), TokenTree::Ident(name), TokenTree::Group(body)] = window else { continue };
        if keyword != "oracle" || body.delimiter() != Delimiter::Brace {
            continue;
        }
        // `pub` or `pub(...)` just before `oracle`.
        let vis_len = match &tokens[..i] {
            [.., word, TokenTree::Group(g)] if is_word(word, "pub") && g.delimiter() == Delimiter::Parenthesis => 2,
            [.., word] if is_word(word, "pub") => 1,
            _ => 0,
        };
        let vis = syn::parse2::<Visibility>(tokens[i - vis_len..i].iter().cloned().collect()).unwrap_or(Visibility::Inherited);
        let body: Vec<TokenTree> = body.stream().into_iter().collect();
        let params = body
            .windows(2)
            .find_map(|w| match w {
                [word, TokenTree::Group(g)] if is_word(word, "params") && g.delimiter() == Delimiter::Brace => {
                    Punctuated::<ParamDecl, Token![,]>::parse_terminated.parse2(g.stream()).ok()
                }
                _ => None,
            })
            .map(|list| list.into_iter().collect())
            .unwrap_or_default();
        items.push(Item::Oracle(OracleDecl {
            attrs: Vec::new(),
            vis,
            keyword: kw::oracle(keyword.span()),
            name: name.clone(),
            params,
            uses: Vec::new(),
            starts: Vec::new(),
            nodes: Vec::new(),
        }));
    }
    Input { krate, items }
}
