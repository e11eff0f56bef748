//! `stats.json` and the figures it holds.

use crate::hierarchy::Hierarchy;
use crate::solve::Solution;

/// Seconds per phase, as written in `stats.json` under `time_s`.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct StatsTimes {
    /// Loading and validating the scene.
    pub load: f64,
    /// Building clusters and the BVH.
    pub build: f64,
    /// Refinement.
    pub refine: f64,
    /// Linear solves, with the leaf-resolution coefficients they are made with.
    pub solve: f64,
    /// Of `solve`: building the leaf-resolution coefficients.
    pub leaf_operator: f64,
    /// The error estimate (solves on coarsened meshes, visibility noise) and the per-level power
    /// balance.
    pub estimate: f64,
    /// Solves after the first, with `solve --time-for` (absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub repeats: Option<f64>,
    /// Writing outputs.
    pub output: f64,
    /// Everything.
    pub total: f64,
    /// Solves timed: build, refine and solve are the fastest of them (1 unless `solve --time-for`
    /// asked for more).
    pub runs: u32,
    /// Gathering the irradiance at calculation points (`solve --points`; absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<f64>,
    /// Gathering the irradiance at the grids' points (`solve --grid` / `--work-plane`; absent
    /// without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grids: Option<f64>,
    /// The importance rounds for points and grids (gathers, subdivisions, solves; absent when
    /// there were none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub importance: Option<f64>,
}

/// The contents of `stats.json` (keys are relied on by other tools; add, never rename).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Stats {
    /// Scene name.
    pub scene: String,
    /// Oracle name.
    pub oracle: String,
    /// Oracle and solver parameters.
    pub params: serde_json::Value,
    /// Input polygons.
    pub polygons: usize,
    /// Elements (clusters and surfaces).
    pub elements: usize,
    /// Leaf elements.
    pub leaves: usize,
    /// Links.
    pub links: usize,
    /// Visibility rays cast.
    pub rays: u64,
    /// Precise form factors computed.
    pub form_factors: u64,
    /// Operator applications over all passes.
    pub iterations: usize,
    /// Refine → solve rounds.
    pub passes: usize,
    /// Final relative residual of the linear system.
    pub residual: f64,
    /// Estimated largest error of a non-emitting polygon's mean radiosity (every channel),
    /// relative to the largest non-emitting polygon mean (see
    /// [`crate::pipeline::Solved::error_estimate`]; null when not estimated).
    pub error_estimate: Option<f64>,
    /// The quantities the estimate covers ([`crate::pipeline::Solved::error_estimate_covers`]).
    pub error_estimate_covers: Vec<&'static str>,
    /// The target error the solve refined to (null when it refined to a fixed eps).
    pub target_error: Option<f64>,
    /// What each refinement level cost and gave, coarse to fine: error against run time.
    pub levels: Vec<crate::pipeline::LevelReport>,
    /// Seconds per phase.
    pub time_s: StatsTimes,
    /// Peak resident memory of the process (bytes), when the platform reports it.
    pub peak_rss_bytes: Option<u64>,
    /// Machinery left out for this scene.
    pub left_out: Vec<String>,
    /// Area-weighted mean radiosity of the leaves [r, g, b] (W/m²).
    pub radiosity_mean: [f64; 3],
    /// Emitted power Σ A·E plus the luminaires' flux (W or lm, summed over channels divided by 3).
    pub power_emitted: f64,
    /// Absorbed power Σ A·(1−ρ)·H (W or lm, same channel mean).
    pub power_absorbed: f64,
    /// Absorbed over emitted power (null when nothing emits): 1 in a closed scene. With daylight,
    /// `(absorbed + escaped) / (emitted + incident)`: 1 when the solve conserves energy.
    pub power_balance: Option<f64>,
    /// Power the sun and sky deliver to the surfaces (W; null without daylight; same channel
    /// mean as `power_absorbed`, or the sum over named bands).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_incident: Option<f64>,
    /// Power leaving the scene (W; null without daylight; see [`crate::daylight::power_leaving`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_escaped: Option<f64>,
    /// Power landing on the back of one-sided faces, blocked there and lost (W; null without
    /// daylight; see [`BandPower::lost_at_backs`]): counted in `power_balance` beside `absorbed`
    /// and `escaped`, and named in `solve_warnings` when above 0.1% of `incident`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_lost_at_backs: Option<f64>,
    /// The scene's bands, when it names them (else the channels are r, g, b).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bands: Vec<String>,
    /// Power per band (or per RGB channel with daylight): emitted, incident, absorbed, escaped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_by_band: Option<std::collections::BTreeMap<String, BandPower>>,
    /// Where the sun is (scenes with a `[sun]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun: Option<crate::daylight::SunReport>,
    /// Sampled fraction of the light leaving the surfaces that escapes the scene (null when not
    /// measured; see [`crate::visibility::escape_fraction`]).
    pub escape_fraction: Option<f64>,
    /// Whether the scene is closed (every surface's light lands on another): the solve then
    /// delivers each surface's light whole.
    pub closed: bool,
    /// Whether refinement stopped at the memory budget.
    pub memory_limited: bool,
    /// What the solve could not do as asked, in words (memory budget reached, target error not
    /// reached).
    pub solve_warnings: Vec<String>,
    /// The target error, when the solve ended without reaching it: the estimate it reached, why
    /// the levels stopped (`memory_budget`, `max_levels`, `no_progress`, `balance_gap`) and the
    /// budget that stopped them (absent when the target was reached or none was set).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_missed: Option<crate::pipeline::TargetMissed>,
    /// What the importance rounds for the calculation points and grids did (absent when there
    /// were none): rounds, leaves split, the worst estimated error of a point set before and
    /// after (relative to the set's largest value), whether it is within the target.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub importance: Option<crate::pipeline::ImportanceReport>,
    /// The leaf-resolution operator was over its budget: coefficients computed again at every
    /// iteration instead of stored (absent when within).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leaf_over_budget: Option<crate::pipeline::LeafOverBudget>,
    /// Stored coefficients and weights of the last leaf-resolution operator.
    pub leaf_operator_entries: usize,
    /// Input warnings (degenerate faces skipped, etc.).
    pub warnings: crate::scene::SceneWarnings,
    /// Calculation points gathered (`solve --points`; absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<usize>,
    /// Visibility rays cast for the calculation points (absent without `--points`; not in `rays`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub point_rays: Option<u64>,
    /// `radiometric` (power in W, radiosity and irradiance in W/m²) or `photometric` (lm, lm/m²,
    /// lx).
    pub units: crate::photometry::Units,
    /// The luminaires (photometric scenes; absent without).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub luminaires: Vec<LuminaireStats>,
    /// In a scene lit by daylight and luminaires together: what each source (every luminaire,
    /// the sun, the sky) brings directly to the surfaces and its share of all of it
    /// ([`crate::luminaire::source_shares`]); absent otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<crate::luminaire::SourceShare>,
    /// The figures of each calculation grid, by name, on the photopic value (`solve --grid` /
    /// `--work-plane`; absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grids: Option<std::collections::BTreeMap<String, crate::points::GridSummary>>,
}

/// The power of one band (or channel) in `stats.json` (W).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct BandPower {
    /// Emitted by the polygons and luminaires.
    pub emitted: f64,
    /// Delivered to the surfaces by the sun and sky.
    pub incident: f64,
    /// Absorbed by the surfaces.
    pub absorbed: f64,
    /// Leaving the scene.
    pub escaped: f64,
    /// Landing on the back of a one-sided face, from the sun and sky (counted in `incident` too)
    /// or from the surfaces: blocked there and lost (see [`crate::daylight::power_leaving`]).
    pub lost_at_backs: f64,
}

impl BandPower {
    /// `(absorbed + escaped + lost_at_backs) / (emitted + incident)` with daylight, else
    /// `absorbed / emitted`.
    #[must_use]
    pub fn balance(&self, daylight: bool) -> Option<f64> {
        let (out, inp) = if daylight {
            (self.absorbed + self.escaped + self.lost_at_backs, self.emitted + self.incident)
        } else {
            (self.absorbed, self.emitted)
        };
        (inp > 0.0).then(|| out / inp)
    }

    /// The sum of `parts`.
    #[must_use]
    pub fn sum(parts: impl IntoIterator<Item = BandPower>) -> BandPower {
        parts.into_iter().fold(BandPower::default(), |a, b| BandPower {
            emitted: a.emitted + b.emitted,
            incident: a.incident + b.incident,
            absorbed: a.absorbed + b.absorbed,
            escaped: a.escaped + b.escaped,
            lost_at_backs: a.lost_at_backs + b.lost_at_backs,
        })
    }
}

/// The power of each channel of a solve (escape and incidence measured only with daylight).
#[must_use]
pub fn channel_powers(solved: &crate::pipeline::Solved) -> [BandPower; 3] {
    channel_powers_and_losses(solved).0
}

/// [`channel_powers`], with the light lost at the backs of one-sided faces per polygon (W summed
/// over channels; empty when none is lost).
#[must_use]
pub fn channel_powers_and_losses(solved: &crate::pipeline::Solved) -> ([BandPower; 3], Vec<f64>) {
    let h = &solved.hierarchy;
    let mut out = [BandPower::default(); 3];
    let lum: f64 = solved.lights.luminaires.iter().map(crate::luminaire::Luminaire::flux).sum();
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let (rho, em, t) = (h.reflectance[p as usize], h.emission[p as usize], h.transmittance[p as usize]);
        let hh = solved.solution.irradiance[leaf as usize];
        for c in 0..3 {
            out[c].emitted += e.area * em[c];
            out[c].absorbed += e.area * (1.0 - rho[c] - t[c]) * hh[c];
        }
    }
    let mut lost_by_polygon = Vec::new();
    if !solved.lights.distant.is_empty() {
        let outside =
            crate::daylight::outside_links(h, &solved.lights.distant, &solved.solution.radiosity, &solved.caster, &solved.escapes);
        for c in 0..3 {
            out[c].incident = outside.incident[c];
            out[c].escaped = outside.escaped[c];
            out[c].lost_at_backs = outside.lost_at_backs[c];
        }
        lost_by_polygon = outside.lost_by_polygon;
        if !solved.lights.luminaires.is_empty() {
            // The leaves' direct light counted as incident holds the luminaires' too: what they
            // bring to the surfaces is emitted (their flux), not incident, and the rest of their
            // flux leaves the scene without touching a surface.
            let onto = crate::luminaire::luminaires_onto_surfaces(h, &solved.lights.luminaires, Some(&solved.caster));
            for c in 0..3 {
                out[c].incident -= onto[c];
                out[c].escaped += (lum - onto[c]).max(0.0);
            }
        }
    }
    for o in &mut out {
        o.emitted += lum;
    }
    (out, lost_by_polygon)
}

/// Share of the incident light (in any channel) landing on the backs of one-sided faces above
/// which the solve warns, naming the faces.
pub const LOST_AT_BACKS_WARN_REL: f64 = 1e-3;

/// How many polygons the lost-at-backs warning names.
const LOST_AT_BACKS_NAMED: usize = 5;

/// The warning for light lost at the backs of one-sided faces (see [`BandPower::lost_at_backs`]),
/// when above [`LOST_AT_BACKS_WARN_REL`] of the incident light in some channel: how much, and the
/// polygons that take most of it.
#[must_use]
pub fn lost_at_backs_warning(scene: &crate::scene::Scene, per: &[BandPower], lost_by_polygon: &[f64]) -> Option<String> {
    let share = per.iter().filter(|p| p.incident > 0.0).map(|p| p.lost_at_backs / p.incident).fold(0.0, f64::max);
    if share <= LOST_AT_BACKS_WARN_REL {
        return None;
    }
    let mut worst: Vec<usize> = (0..lost_by_polygon.len()).filter(|&p| lost_by_polygon[p] > 0.0).collect();
    let faces = worst.len();
    worst.sort_by(|&a, &b| lost_by_polygon[b].total_cmp(&lost_by_polygon[a]).then(a.cmp(&b)));
    let named: Vec<String> = worst
        .iter()
        .take(LOST_AT_BACKS_NAMED)
        .map(|&p| {
            let polygon = &scene.polygons[p];
            let group = scene.groups.get(polygon.group as usize).map_or("", String::as_str);
            format!("{p} (group `{group}`, material `{}`)", scene.materials[polygon.material as usize].name)
        })
        .collect();
    Some(format!(
        "{}: {:.2}% of the incident light lands on the back of one-sided faces and is lost there ({faces} faces; most on polygons {}, 0-based in input order): give their material `two_sided = true` (OBJ: `two_sided 1` in the MTL) for a back that reflects like the front, or leave them one-sided where the backs are really hidden",
        scene.name,
        100.0 * share,
        named.join(", ")
    ))
}

/// One luminaire in `stats.json`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LuminaireStats {
    /// Its name.
    pub name: String,
    /// The flux leaving it (lm): its photometric file's, integrated, times its multiplier.
    pub flux_lm: f64,
    /// The lamps' flux its file declares, times its multiplier (lm; null when the file gives
    /// absolute photometry).
    pub declared_lm: Option<f64>,
}

/// Peak resident set size of this process (`VmHWM` on Linux).
#[must_use]
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// `(emitted, absorbed, mean radiosity)`: emitted and absorbed power per channel mean, and the
/// area-weighted mean leaf radiosity.
#[must_use]
pub fn power_balance(h: &Hierarchy, lights: &crate::light::Lights, solution: &Solution) -> (f64, f64, [f64; 3]) {
    let mut emitted = 0.0;
    let mut absorbed = 0.0;
    let mut mean = [0.0; 3];
    let mut area = 0.0;
    for leaf in h.leaves() {
        let e = h.get(leaf);
        let Some(p) = e.polygon() else { continue };
        let (rho, em, t) = (h.reflectance[p as usize], h.emission[p as usize], h.transmittance[p as usize]);
        let hh = solution.irradiance[leaf as usize];
        let b = solution.radiosity[leaf as usize];
        for c in 0..3 {
            emitted += e.area * em[c] / 3.0;
            absorbed += e.area * (1.0 - rho[c] - t[c]) * hh[c] / 3.0;
            mean[c] += e.area * b[c];
        }
        area += e.area;
    }
    // The luminaires' light (every channel the same luminous flux).
    emitted += lights.luminaires.iter().map(crate::luminaire::Luminaire::flux).sum::<f64>();
    (emitted, absorbed, mean.map(|m| if area > 0.0 { m / area } else { 0.0 }))
}

impl Stats {
    /// The figures of a finished solve. `load` is the loading time, `output` the time spent writing
    /// files (0 when not yet known), `total` the wall time of the whole command.
    #[must_use]
    pub fn from_solved(
        scene: &crate::scene::Scene,
        solved: &crate::pipeline::Solved,
        oracle: &str,
        params: serde_json::Value,
        times: (f64, f64, f64),
    ) -> Stats {
        let (load, output, total) = times;
        let h = &solved.hierarchy;
        let (power_emitted, power_absorbed, radiosity_mean) = power_balance(h, &solved.lights, &solved.solution);
        let mut stats = Stats {
            scene: scene.name.clone(),
            oracle: oracle.to_string(),
            params,
            polygons: scene.polygons.len(),
            elements: h.len(),
            leaves: h.leaves().count(),
            links: solved.links.len(),
            rays: solved.rays,
            form_factors: solved.refine_stats.form_factors,
            iterations: solved.iterations,
            passes: solved.passes,
            residual: solved.solution.residual,
            error_estimate: solved.error_estimate,
            error_estimate_covers: solved.error_estimate_covers.clone(),
            target_error: None,
            levels: solved.levels.clone(),
            time_s: StatsTimes {
                load,
                build: solved.timings.build,
                refine: solved.timings.refine,
                solve: solved.timings.solve,
                leaf_operator: solved.timings.leaf_operator,
                estimate: solved.timings.estimate,
                repeats: None,
                output,
                total,
                runs: 1,
                points: None,
                grids: None,
                importance: solved.importance.is_some().then_some(solved.timings.importance),
            },
            peak_rss_bytes: peak_rss_bytes(),
            left_out: solved.left_out.clone(),
            radiosity_mean,
            power_emitted,
            power_absorbed,
            power_balance: (power_emitted > 0.0).then(|| power_absorbed / power_emitted),
            power_incident: None,
            power_escaped: None,
            power_lost_at_backs: None,
            bands: Vec::new(),
            power_by_band: None,
            sun: None,
            escape_fraction: solved.escape_fraction.is_finite().then_some(solved.escape_fraction),
            closed: solved.closed,
            memory_limited: solved.memory_limited,
            solve_warnings: solved.warnings.clone(),
            target_missed: solved.target_missed,
            importance: solved.importance,
            leaf_over_budget: solved.leaf_over_budget,
            leaf_operator_entries: solved.leaf_entries,
            warnings: scene.warnings.clone(),
            points: None,
            point_rays: None,
            units: scene.units,
            luminaires: solved
                .lights
                .luminaires
                .iter()
                .map(|l| LuminaireStats {
                    name: l.name.clone(),
                    flux_lm: l.flux(),
                    declared_lm: l.photometry.declared_lumens.map(|d| d * l.multiplier),
                })
                .collect(),
            sources: Vec::new(),
            grids: None,
        };
        if !solved.lights.luminaires.is_empty() && !solved.lights.distant.is_empty() {
            stats.sources = crate::luminaire::source_shares(h, &solved.lights.luminaires, &solved.lights.distant, Some(&solved.caster));
        }
        if !solved.lights.distant.is_empty() {
            let (per, lost_by_polygon) = channel_powers_and_losses(solved);
            stats.set_band_powers(&crate::output::csv::RGB, &per, true);
            stats.solve_warnings.extend(lost_at_backs_warning(scene, &per, &lost_by_polygon));
        }
        stats
    }

    /// Sets the power figures from per-band powers: the scalars are the mean over RGB channels
    /// (each carries the whole power) or the sum over named bands (each a part of the spectrum).
    pub fn set_band_powers(&mut self, names: &[impl AsRef<str>], per: &[BandPower], daylight: bool) {
        let total = BandPower::sum(per.iter().copied());
        let rgb = names.len() == 3 && names.iter().zip(crate::output::csv::RGB).all(|(a, b)| a.as_ref() == b);
        let scale = if rgb { 1.0 / 3.0 } else { 1.0 };
        self.power_emitted = total.emitted * scale;
        self.power_absorbed = total.absorbed * scale;
        if daylight {
            self.power_incident = Some(total.incident * scale);
            self.power_escaped = Some(total.escaped * scale);
            self.power_lost_at_backs = Some(total.lost_at_backs * scale);
        }
        self.power_balance = total.balance(daylight);
        self.power_by_band = Some(names.iter().map(|n| n.as_ref().to_owned()).zip(per.iter().copied()).collect());
    }
}
