//! Named contexts (vertices, colours, materials): mgflib's `c_hvertex` / `c_hcolor` /
//! `c_hmaterial` selection rules, shared by the three kinds.

use std::collections::HashMap;

/// A table of named contexts plus the unnamed one, and which of them is current (mgflib's `c_h*`).
pub(super) struct Contexts<T> {
    /// Contexts by name.
    pub named: HashMap<Box<str>, T>,
    /// The unnamed context.
    pub unnamed: T,
    /// Name of the current context; `None` for the unnamed one.
    pub current: Option<Box<str>>,
}

impl<T: Clone> Contexts<T> {
    /// A table with only the unnamed context.
    pub fn new(unnamed: T) -> Contexts<T> {
        Contexts { named: HashMap::new(), unnamed, current: None }
    }

    /// The current context.
    pub fn current(&self) -> &T {
        self.current.as_ref().and_then(|n| self.named.get(n)).unwrap_or(&self.unnamed)
    }

    /// The current context, to change it.
    pub fn current_mut(&mut self) -> &mut T {
        match self.current.as_ref().and_then(|n| self.named.get_mut(n)) {
            Some(ctx) => ctx,
            None => &mut self.unnamed,
        }
    }

    /// `e` (reset the unnamed context), `e name` (select), `e name =` (define from `default`) or
    /// `e name = template` (define as a copy). The error says what is wrong.
    pub fn select(&mut self, words: &[Box<str>], default: T, kind: &str) -> Result<(), String> {
        match words {
            [_] => {
                self.unnamed = default;
                self.current = None;
            }
            [_, name] => {
                if !self.named.contains_key(name) {
                    return Err(format!("undefined {kind} `{name}`"));
                }
                self.current = Some(name.clone());
            }
            [_, name, eq, rest @ ..] if rest.len() <= 1 => {
                if &**eq != "=" {
                    return Err(format!("expected `=` after {kind} name `{name}`, found `{eq}`"));
                }
                let value = match rest.first() {
                    Some(template) => self.named.get(template).cloned().ok_or_else(|| format!("undefined {kind} `{template}`"))?,
                    None => default,
                };
                self.named.insert(name.clone(), value);
                self.current = Some(name.clone());
            }
            _ => return Err(format!("`{}` takes at most 3 arguments", words[0])),
        }
        Ok(())
    }
}
