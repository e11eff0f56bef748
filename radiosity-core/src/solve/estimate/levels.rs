//! How much each refinement level changed the polygon means, and the floor that puts under the
//! error estimate of a target error.

/// Factor on the last refinement level's change of the polygon means that the error estimate
/// under a target error is at least ([`LevelHistory`], `pipeline`'s levels), polygon by polygon
/// and for the largest. Finer links change what coarsening the mesh under the same links cannot
/// show: a link takes its source's radiosity as uniform and its visibility as one fraction over
/// its receiver. On interiors lit by many small lamps among furniture the mesh's estimate fell
/// below the true error (the generated classroom at a 10% target: 6.4% for 9.7%; RenderPark's
/// cube at 0.3%: 0.19% for 0.22–0.51% against two finer solves), while the last level's change
/// showed it. Measured at the default target (`radiosity bench accuracy`, `bench renderpark`,
/// 2026-12-06), the true error was 0.61 to 1.23 times the last change (Ward's room 0.89, the
/// corner rooms 0.61–1.23, the cube 1.05): 1.5 keeps a fifth above the largest.
pub const LEVEL_CHANGE_SAFETY: f64 = 1.5;

/// The polygon means of successive refinement levels, and how much each level changed them.
#[derive(Clone, Debug, Default)]
pub struct LevelHistory {
    /// Which polygons emit (left out of the measure).
    emitting: Vec<bool>,
    /// The last level's polygon means.
    last: Option<Vec<[f64; 3]>>,
    /// The changes between consecutive levels.
    changes: Vec<f64>,
    /// Each polygon's change over the last level (largest channel, absolute; empty before the
    /// second level).
    polygon_changes: Vec<f64>,
    /// Which polygons the level being refined now refines further (empty: all), see
    /// [`LevelHistory::refining`].
    refined: Vec<bool>,
    /// Each polygon's change the floor reads: its own over the last level it was refined at, or
    /// what its sources changed it by since, whichever is larger.
    floor_changes: Vec<f64>,
    /// The largest of `floor_changes` over the measured polygons, relative to the largest
    /// non-emitting mean.
    floor_change: Option<f64>,
}

impl LevelHistory {
    /// A history for a scene whose polygons emit where `emitting` says. When every polygon emits (a
    /// furnace), every polygon is measured.
    #[must_use]
    pub fn new(mut emitting: Vec<bool>) -> LevelHistory {
        if emitting.iter().all(|&e| e) {
            emitting.fill(false);
        }
        LevelHistory { emitting, ..LevelHistory::default() }
    }

    /// Says which polygons the next level refines further for their own error (local levels,
    /// `pipeline`'s `Config::local_levels`): any other keeps the largest change it showed since
    /// the last level that did as its floor ([`LevelHistory::floor_by_change`]), for a level that
    /// does not refine its links cannot show what they miss.
    pub fn refining(&mut self, refined: Vec<bool>) {
        self.refined = refined;
    }

    /// Records a level's polygon means; returns the change since the level before (relative to the
    /// largest non-emitting mean), `None` for the first.
    pub fn push(&mut self, means: Vec<[f64; 3]>) -> Option<f64> {
        let change = self.last.as_ref().map(|last| {
            self.polygon_changes = means.iter().zip(last).map(|(m, l)| (0..3).map(|c| (m[c] - l[c]).abs()).fold(0.0, f64::max)).collect();
            let held = std::mem::take(&mut self.floor_changes);
            let refined = std::mem::take(&mut self.refined);
            self.floor_changes = (self.polygon_changes.iter().enumerate())
                .map(|(p, &d)| if refined.get(p).is_none_or(|&r| r) { d } else { d.max(held.get(p).copied().unwrap_or(0.0)) })
                .collect();
            let lit = || (0..means.len()).filter(|&p| !self.emitting[p]);
            let top = lit().flat_map(|p| means[p]).fold(0.0, f64::max);
            let relative = |changes: &[f64]| if top > 0.0 { lit().map(|p| changes[p]).fold(0.0, f64::max) / top } else { 0.0 };
            self.floor_change = Some(relative(&self.floor_changes));
            relative(&self.polygon_changes)
        });
        if let Some(d) = change {
            self.changes.push(d);
        }
        self.last = Some(means);
        change
    }

    /// An error estimate under a target error raised to [`LEVEL_CHANGE_SAFETY`] times the last
    /// level's change: the whole (`estimate`, relative) by the largest change, each polygon's
    /// (`per_polygon`, W/m²) by its own. A polygon the last level did not refine
    /// ([`LevelHistory::refining`]) keeps the change of the last level that did as its floor.
    /// Unchanged before the second level.
    #[must_use]
    pub fn floor_by_change(&self, estimate: f64, per_polygon: Vec<f64>) -> (f64, Vec<f64>) {
        let Some(change) = self.floor_change else { return (estimate, per_polygon) };
        let per_polygon = per_polygon
            .into_iter()
            .enumerate()
            .map(|(p, e)| e.max(LEVEL_CHANGE_SAFETY * self.floor_changes.get(p).copied().unwrap_or(0.0)))
            .collect();
        (estimate.max(LEVEL_CHANGE_SAFETY * change), per_polygon)
    }

    /// Each polygon's change over the last level, largest channel, absolute (W/m²); empty until
    /// two levels are recorded.
    #[must_use]
    pub fn polygon_changes(&self) -> &[f64] {
        &self.polygon_changes
    }

    /// The changes between consecutive levels so far.
    #[must_use]
    pub fn changes(&self) -> &[f64] {
        &self.changes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The change of each level, relative to the largest non-emitting mean, and each polygon's
    /// own over the last level (emitters' too: the estimate's per-polygon floor).
    #[test]
    fn level_history_changes_overall_and_per_polygon() {
        let mut history = LevelHistory::new(vec![false, true, false]);
        assert_eq!(history.push(vec![[1.0; 3], [100.0; 3], [4.0; 3]]), None);
        assert!(history.polygon_changes().is_empty());
        let change = history.push(vec![[1.5, 1.0, 1.0], [90.0; 3], [3.8, 4.0, 4.0]]).expect("a change");
        assert!((change - 0.5 / 4.0).abs() < 1e-12, "{change}");
        let per_polygon = history.polygon_changes();
        assert_eq!(per_polygon.len(), 3);
        for (got, want) in per_polygon.iter().zip([0.5, 10.0, 0.2]) {
            assert!((got - want).abs() < 1e-12, "{per_polygon:?}");
        }
        assert_eq!(history.changes().len(), 1);
    }

    /// A polygon a level leaves as it was keeps the change of the last level that refined it as
    /// its floor, unless what it changes by now is larger; a refined one takes its new change.
    #[test]
    fn level_history_holds_the_change_of_polygons_left_as_they_were() {
        let mut history = LevelHistory::new(vec![false, false, false]);
        history.push(vec![[10.0; 3], [4.0; 3], [2.0; 3]]);
        history.push(vec![[10.0; 3], [4.4; 3], [2.2; 3]]);
        history.refining(vec![true, false, false]);
        let change = history.push(vec![[10.1; 3], [4.41; 3], [2.5; 3]]).expect("a change");
        assert!((change - 0.3 / 10.1).abs() < 1e-9, "{change}");
        let (estimate, per_polygon) = history.floor_by_change(0.0, vec![0.0; 3]);
        for (got, want) in per_polygon.iter().zip([0.1, 0.4, 0.3]) {
            assert!((got - LEVEL_CHANGE_SAFETY * want).abs() < 1e-9, "{per_polygon:?}");
        }
        assert!((estimate - LEVEL_CHANGE_SAFETY * 0.4 / 10.1).abs() < 1e-9, "{estimate}");
        // The mask is for one level: the next refines every polygon again.
        history.push(vec![[10.1; 3], [4.42; 3], [2.5; 3]]);
        let (_, per_polygon) = history.floor_by_change(0.0, vec![0.0; 3]);
        assert!((per_polygon[1] - LEVEL_CHANGE_SAFETY * 0.01).abs() < 1e-9, "{per_polygon:?}");
    }
}
