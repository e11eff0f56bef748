//! Nesting: groups of the object stack, `o`, `xf` (with arrays), `i` includes, and skipped
//! entities.

use super::{GROUP_SEPARATOR, ROOT_GROUP, Reader, Skipped, XfFrame};
use crate::scene::SceneError;
use crate::scene::mgf::lines::Entity;
use crate::scene::mgf::xform::{self, XfSpec};
use glam::DAffine3;
use std::path::{Component, Path, PathBuf};

impl Reader {
    /// Scene group of the current object path.
    pub(super) fn group_id(&mut self) -> u32 {
        if let Some(id) = self.group_id {
            return id;
        }
        let id =
            if self.objects.is_empty() { self.builder.group(ROOT_GROUP) } else { self.builder.group(&self.objects.join(GROUP_SEPARATOR)) };
        self.group_id = Some(id);
        id
    }

    pub(super) fn object(&mut self, e: &Entity) -> Result<(), SceneError> {
        match &e.words[..] {
            [_] => {
                if self.objects.pop().is_none() {
                    self.warn_at(e.line, "`o` closes no object; ignored".into());
                }
            }
            [_, name] => self.objects.push(name.clone()),
            _ => return Err(self.parse_err(e.line, "`o` takes at most one name")),
        }
        self.group_id = None;
        Ok(())
    }

    /// `xf args` opens a transform; `xf` closes it or starts its next array instance.
    pub(super) fn xf(&mut self, e: &Entity, run: usize, next: usize) -> Result<Option<usize>, SceneError> {
        if e.words.len() > 1 {
            let spec = XfSpec::parse(&e.words[1..]).map_err(|m| self.parse_err(e.line, m))?;
            self.push_xf(spec, run, next, false, e.line)?;
            return Ok(None);
        }
        match self.xf.last() {
            Some(f) if f.run == run && !f.include => {}
            Some(_) => return Err(self.parse_err(e.line, "`xf` closes a transform opened in another file")),
            None => return Err(self.parse_err(e.line, "`xf` closes no transform")),
        }
        if self.next_instance() {
            return Ok(self.xf.last().map(|f| f.resume));
        }
        self.pop_xf();
        Ok(None)
    }

    pub(super) fn push_xf(&mut self, spec: XfSpec, run: usize, resume: usize, include: bool, line: usize) -> Result<(), SceneError> {
        let mut sizes = self.xf.iter().flat_map(|f| &f.spec.array_sizes).chain(&spec.array_sizes);
        if sizes.try_fold(1usize, |acc, &n| acc.checked_mul(n)).is_none_or(|n| n > xform::MAX_INSTANCES) {
            return Err(
                self.parse_err(line, format!("array transform makes over {} instances (counting enclosing arrays)", xform::MAX_INSTANCES))
            );
        }
        let parent = self.xf.last().map_or(DAffine3::IDENTITY, |f| f.to_world);
        let idx = vec![0; spec.array_sizes.len()];
        let objects_base = (!idx.is_empty()).then_some(self.objects.len());
        let mut frame = XfFrame { spec, idx, parent, to_world: parent, reversed: false, run, resume, include, line, objects_base };
        frame.update();
        self.xf.push(frame);
        self.push_instance_name();
        Ok(())
    }

    /// Moves the innermost transform to its next array instance; false when it has none left.
    pub(super) fn next_instance(&mut self) -> bool {
        let Some(f) = self.xf.last_mut() else { return false };
        let Some(base) = f.objects_base else { return false };
        if !xform::next_instance(&mut f.idx, &f.spec.array_sizes) {
            return false;
        }
        f.update();
        self.objects.truncate(base);
        self.push_instance_name();
        true
    }

    /// Array instances are objects named `a<i>` (`a<i>.<j>` ... for several `-a`), as in mgflib.
    fn push_instance_name(&mut self) {
        if let Some(f) = self.xf.last().filter(|f| f.objects_base.is_some()) {
            let idx: Vec<String> = f.idx.iter().map(usize::to_string).collect();
            self.objects.push(format!("a{}", idx.join(".")).into());
            self.group_id = None;
        }
    }

    pub(super) fn pop_xf(&mut self) {
        if let Some(base) = self.xf.pop().and_then(|f| f.objects_base) {
            self.objects.truncate(base);
            self.group_id = None;
        }
    }

    /// `i file [xf args]`: reads `file` (relative to the including file) under the transform.
    pub(super) fn include(&mut self, e: &Entity) -> Result<(), SceneError> {
        let Some(name) = e.words.get(1) else {
            return Err(self.parse_err(e.line, "`i` needs a file name"));
        };
        let spec = match e.words.len() > 2 {
            true => Some((XfSpec::parse(&e.words[2..]).map_err(|m| self.parse_err(e.line, m))?, e.line)),
            false => None,
        };
        let here = self.current_path();
        // Relative to the including file; `./` components dropped so that messages read cleanly.
        let path: PathBuf = here.parent().unwrap_or(Path::new("")).join(&**name).components().filter(|c| *c != Component::CurDir).collect();
        let line = e.line;
        let src = self.open(&path, None).map_err(|err| match err {
            // Named at the `i` line, with the reason, so the message says where the include is.
            SceneError::Io { path, source } => self.parse_err(line, format!("cannot read included file `{}`: {source}", path.display())),
            other => other,
        })?;
        if let Some(pos) = self.files.iter().position(|f| f.key == src.key) {
            let chain: Vec<String> = self.files[pos..].iter().chain([&src]).map(|f| f.path.display().to_string()).collect();
            return Err(self.parse_err(e.line, format!("include cycle: {}", chain.join(" -> "))));
        }
        self.run(src, spec)
    }

    /// Skips an entity with one warning per entity kind (counted).
    pub(super) fn skip(&mut self, e: &Entity, what: &str) {
        let path = self.current_path();
        let n_messages = self.builder.warnings_mut().messages.len();
        let entry = self.skipped.entry(e.words[0].clone()).or_insert(Skipped { count: 0, message_idx: None });
        if entry.count == 0 {
            self.builder.warn(format!("{}:{}: {what} `{}` skipped", path.display(), e.line, e.words[0]));
            if self.builder.warnings_mut().messages.len() > n_messages {
                entry.message_idx = Some(n_messages);
            }
        }
        entry.count += 1;
    }
}
