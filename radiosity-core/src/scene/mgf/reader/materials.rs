//! Colours and materials: `cxy`, `cspec`, `cct`, `cmix`, the material properties, and the scene
//! material a face gets.

use super::{ColorValue, Reader, UNNAMED_MATERIAL};
use crate::scene::mgf::color::{self, Chroma};
use crate::scene::mgf::lines::{Entity, parse_int};
use crate::scene::{Material, SceneError};
use std::rc::Rc;

impl Reader {
    /// `cxy`, `cspec`, `cct` or `cmix`: the new value of the current colour.
    pub(super) fn color(&self, e: &Entity) -> Result<ColorValue, SceneError> {
        let (w, line) = (&e.words, e.line);
        match &*w[0] {
            "cxy" => {
                let [x, y] = self.floats::<2>(e)?;
                Chroma::new(x, y)
                    .map(Ok)
                    .ok_or_else(|| self.parse_err(line, format!("chromaticity ({x}, {y}) outside x, y >= 0, x + y <= 1")))
            }
            "cspec" => {
                if w.len() < 5 {
                    return Err(self.parse_err(line, "`cspec` needs a wavelength range and at least 2 values"));
                }
                let values = w[1..].iter().map(|v| self.float(v, line)).collect::<Result<Vec<f64>, _>>()?;
                Ok(color::from_spectrum(values[0], values[1], &values[2..]).ok_or_else(|| {
                    let path = self.current_path();
                    Rc::from(format!(
                        "the colour set by `cspec` at {}:{line} has no valid chromaticity (its spectrum gives negative or zero tristimulus values)",
                        path.display()
                    ))
                }))
            }
            "cct" => {
                let [kelvin] = self.floats::<1>(e)?;
                color::from_temperature(kelvin).map(Ok).ok_or_else(|| {
                    self.parse_err(line, format!("colour temperature {kelvin} K is below {} K", color::MIN_COLOR_TEMPERATURE))
                })
            }
            _ => {
                // `cmix w1 c1 w2 c2 ...`
                if w.len() < 5 || w.len() % 2 == 0 {
                    return Err(self.parse_err(line, "`cmix` needs pairs of weight and colour name, at least 2"));
                }
                let mut parts = Vec::with_capacity(w.len() / 2);
                for pair in w[1..].chunks(2) {
                    let weight = self.float(&pair[0], line)?;
                    let c =
                        self.colors.named.get(&pair[1]).ok_or_else(|| self.parse_err(line, format!("undefined colour `{}`", pair[1])))?;
                    parts.push((weight, c.clone().map_err(|why| self.parse_err(line, format!("colour `{}`: {why}", pair[1])))?));
                }
                color::mix(&parts)
                    .map(Ok)
                    .ok_or_else(|| self.parse_err(line, "`cmix` weights must sum to a positive value (and colours need y > 0)"))
            }
        }
    }

    /// `rd`, `td`, `ed` (with the current colour) or `sides` of the current material.
    pub(super) fn material_property(&mut self, e: &Entity) -> Result<(), SceneError> {
        let at = self.location(e.line);
        if &*e.words[0] == "sides" {
            self.n_args(e, 1)?;
            let one_sided = match parse_int(&e.words[1]) {
                Some(1) => true,
                Some(2) => false,
                _ => return Err(self.parse_err(e.line, format!("`sides` must be 1 or 2, found `{}`", e.words[1]))),
            };
            self.materials.current_mut().one_sided = one_sided;
        } else {
            let [value] = self.floats::<1>(e)?;
            if value < 0.0 {
                return Err(self.parse_err(e.line, format!("`{}` must not be negative", e.words[0])));
            }
            let color = self.colors.current().clone().map_err(|why| self.parse_err(e.line, why.to_string()))?;
            let value = (value, color);
            let m = self.materials.current_mut();
            match &*e.words[0] {
                "rd" => m.rd = value,
                "td" => m.td = value,
                _ => m.ed = value,
            }
        }
        self.materials.current_mut().at = at;
        self.material_id = None;
        Ok(())
    }

    /// Scene material of the current material context (made on first use after each change).
    pub(super) fn material_id(&mut self) -> Result<u32, SceneError> {
        if let Some(id) = self.material_id {
            return Ok(id);
        }
        let name: Box<str> = self.materials.current.clone().unwrap_or_else(|| UNNAMED_MATERIAL.into());
        let ctx = self.materials.current();
        let (mut material, clamped) = ctx.to_material(&name, self.options.force_one_sided);
        let at = ctx.at.clone();
        let versions = self.emitted.entry(name.clone()).or_default();
        let same = |m: &Material| {
            m.reflectance == material.reflectance
                && m.emission == material.emission
                && m.transmittance == material.transmittance
                && m.two_sided == material.two_sided
        };
        let id = match versions.iter().find(|(m, _)| same(m)) {
            Some(&(_, id)) => id,
            None => {
                let mut k = 1;
                while self.used_material_names.contains(&material.name) {
                    k += 1;
                    material.name = format!("{name}#{k}");
                }
                self.used_material_names.insert(material.name.clone());
                if let Some(why) = clamped {
                    self.builder.warnings_mut().clamped_materials += 1;
                    self.builder.warn(format!("{}:{}: material `{}`: {why}", at.path.display(), at.line, material.name));
                }
                let id = self.builder.material(material.clone())?;
                versions.push((material, id));
                id
            }
        };
        self.material_id = Some(id);
        Ok(id)
    }
}
