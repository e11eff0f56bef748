//! Light sources other than emitting polygons: photometric luminaires ([`Luminaire`]) and distant
//! sources, the sun and the sky's cells ([`DistantSource`]), held together as a scene's
//! [`Lights`].
//!
//! The contract of this layer: a source says what it sends toward a point (a luminaire's intensity
//! and the illuminance it gives a receiver, a distant source's irradiance on a plane), unoccluded;
//! it knows geometry and photometry only. It does not know the hierarchy, which does not know it
//! either: the hierarchy keeps only each element's direct irradiance (numbers), filled by
//! [`crate::luminaire::update_direct`] from the lights and a ray caster. What uses both (direct
//! light on elements, the power balance, the statistics) takes the lights beside the hierarchy.

pub mod distant;
pub mod luminaire;

pub use distant::{DistantSource, SkyPatch};
pub use luminaire::{Luminaire, LuminaireError};

/// Every light source of a scene besides its emitting polygons.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    /// Photometric luminaires.
    pub luminaires: Vec<Luminaire>,
    /// The sun and the sky's cells.
    pub distant: Vec<DistantSource>,
}

impl Lights {
    /// Whether there is no source at all (the scene is lit by its emitting polygons only).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.luminaires.is_empty() && self.distant.is_empty()
    }
}

#[cfg(test)]
mod tests {
    /// The code lines (comments and tests left out) of every `.rs` file under `src/<folder>`.
    fn code_of(folder: &str) -> Vec<(String, String)> {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(folder);
        let mut out = Vec::new();
        let mut stack = vec![dir];
        while let Some(d) = stack.pop() {
            for entry in std::fs::read_dir(&d).expect("source folder") {
                let path = entry.expect("entry").path();
                if path.is_dir() {
                    stack.push(path);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    let text = std::fs::read_to_string(&path).expect("source file");
                    // Up to the tests, which may use anything.
                    let code = text.lines().take_while(|l| l.trim() != "#[cfg(test)]");
                    for line in code.filter(|l| !l.trim_start().starts_with("//")) {
                        out.push((path.display().to_string(), line.to_owned()));
                    }
                }
            }
        }
        out
    }

    /// The layering this module's docs state: the hierarchy knows no light source, and the light
    /// sources know geometry and photometry only.
    #[test]
    fn hierarchy_and_lights_do_not_know_each_other() {
        for (file, line) in code_of("hierarchy") {
            for upper in ["crate::light", "crate::luminaire", "crate::daylight"] {
                assert!(!line.contains(upper), "{file} uses `{upper}`: {line}");
            }
        }
        for (file, line) in code_of("light") {
            let mut rest = line.as_str();
            while let Some(i) = rest.find("crate::") {
                rest = &rest[i + "crate::".len()..];
                assert!(
                    ["geom", "photometry", "light"].iter().any(|m| rest.starts_with(m)),
                    "{file} uses a layer above the light sources: {line}"
                );
            }
        }
    }
}
