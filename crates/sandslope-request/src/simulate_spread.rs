//! The contact scaling as model uncertainty in simulate's answers (issue 59 item 4; field
//! `scaling-spread`, docs/simulate.md, "The scaling as model uncertainty"): each slope walked
//! under all three scalings, the range of their speeds and whether their regimes agree.

use serde::Serialize;

use sandslope::simulate::{simulate_slopes, RftScaling, ScalingSpread, SimSummary, Simulation, SCALINGS};
use sandslope::Regime;

use crate::error::Result;
use crate::simulate::{sim_err, Walks};

/// One slope's walk as `simulate --json` prints it: the walk's summary, its keys at the top,
/// and `scaling_spread` (`null` where it was not asked).
#[derive(Debug, Clone, Serialize)]
pub struct SimAnswer {
    /// The walk under the asked scaling.
    #[serde(flatten)]
    pub summary: SimSummary,
    /// The same slope under all three scalings (field `scaling-spread`).
    pub scaling_spread: Option<SpreadAnswer>,
}

/// One slope walked under each of the three contact scalings: the model uncertainty of a choice
/// the sand is not measured to make (docs/simulate.md, "The scaling as model uncertainty").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpreadAnswer {
    /// The smallest of the three walks' speeds, m/s.
    pub min_speed_m_s: f64,
    /// The largest, m/s.
    pub max_speed_m_s: f64,
    /// The largest less the smallest, m/s.
    pub range_m_s: f64,
    /// Whether the three walks end in the same regime (where they do not, the slope's verdict
    /// is the scaling's, not the sand's).
    pub regimes_agree: bool,
    /// Each scaling's walk, in the order motion, li2013, components.
    pub walks: Vec<ScalingWalk>,
}

/// One scaling's walk in a [`SpreadAnswer`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScalingWalk {
    /// The scaling (`motion`, `li2013` or `components`).
    pub rft_scaling: RftScaling,
    /// Its mean step speed, m/s.
    pub speed_m_s: f64,
    /// Its regime.
    pub regime: Regime,
    /// Its mean anchoring time, s (`null`: no step anchored).
    pub t1_s: Option<f64>,
}

impl SpreadAnswer {
    /// The answer's view of the library's spread.
    pub fn of(spread: &ScalingSpread) -> SpreadAnswer {
        SpreadAnswer {
            min_speed_m_s: spread.min_speed_m_s,
            max_speed_m_s: spread.max_speed_m_s,
            range_m_s: spread.max_speed_m_s - spread.min_speed_m_s,
            regimes_agree: spread.regimes_agree,
            walks: spread
                .walks
                .iter()
                .map(|w| ScalingWalk {
                    rft_scaling: w.rft_scaling,
                    speed_m_s: w.speed_m_s,
                    regime: w.regime,
                    t1_s: w.t1_s,
                })
                .collect(),
        }
    }
}

impl Walks {
    /// The walks as asked ([`Walks::simulate`]) and, where asked, each slope's scaling spread
    /// ([`Walks::spreads`]), the three scalings' walks at once (in parallel: a one-slope walk is
    /// one thread's work, and the two other scalings used to start only after it ended).
    pub fn simulate_with_spreads(&self) -> Result<(Vec<Simulation>, Vec<Option<SpreadAnswer>>)> {
        if !self.scaling_spread {
            let sims = self.simulate()?;
            let none = vec![None; sims.len()];
            return Ok((sims, none));
        }
        let (sims, others) = rayon::join(|| self.simulate(), || self.other_scalings());
        let sims = sims?;
        let spreads = self.spreads_beside(&sims, others?);
        Ok((sims, spreads))
    }

    /// The two scalings other than the asked one, and each one's walks of every slope (the two
    /// in parallel, each over the slopes in parallel).
    fn other_scalings(&self) -> Result<[(RftScaling, Vec<Simulation>); 2]> {
        let asked = self.settings.rft_scaling;
        let others: Vec<RftScaling> = SCALINGS.into_iter().filter(|&s| s != asked).collect();
        let walk = |s: RftScaling| {
            simulate_slopes(&self.scenario, &self.slopes, &self.settings.with_rft_scaling(s))
                .map_err(|e| sim_err(e, self.words))
        };
        let (a, b) = rayon::join(|| walk(others[0]), || walk(others[1]));
        Ok([(others[0], a?), (others[1], b?)])
    }

    /// Each slope's spread: `sims` (the asked scaling's) beside `others`.
    fn spreads_beside(
        &self,
        sims: &[Simulation],
        others: [(RftScaling, Vec<Simulation>); 2],
    ) -> Vec<Option<SpreadAnswer>> {
        let asked = self.settings.rft_scaling;
        sims.iter()
            .enumerate()
            .map(|(i, own)| {
                let walks = SCALINGS
                    .iter()
                    .map(|&s| {
                        let sim = if s == asked {
                            own
                        } else if s == others[0].0 {
                            &others[0].1[i]
                        } else {
                            &others[1].1[i]
                        };
                        sim.summary.clone()
                    })
                    .collect();
                Some(SpreadAnswer::of(&ScalingSpread::of_walks(own.summary.slope_deg, walks)))
            })
            .collect()
    }

    /// The scaling spread of each slope (in slope order), `None` each where it is not asked:
    /// `sims` (these walks' own, under the asked scaling) beside the same slopes walked under
    /// the other two scalings (the two in parallel, each over the slopes in parallel).
    pub fn spreads(&self, sims: &[Simulation]) -> Result<Vec<Option<SpreadAnswer>>> {
        if !self.scaling_spread {
            return Ok(vec![None; sims.len()]);
        }
        Ok(self.spreads_beside(sims, self.other_scalings()?))
    }
}

#[cfg(test)]
mod tests {
    use sandslope::simulate::simulate;

    use super::*;
    use crate::simulate::{Answer, SimulateRequest};

    fn params(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
        pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    /// One slope answers its spread by default, and the spread is the three walks' own: each
    /// scaling walked here on its own, the range bounding their speeds and reached by two of
    /// them. At 24 degrees on the built-in terrain the regimes part (docs/simulate.md, "The
    /// scaling as model uncertainty": `motion` slides back, the stance tripod's mid-stance push
    /// below m g sin 24; `components` climbs).
    #[test]
    fn one_slope_carries_the_spread_of_the_three_scalings_walked_apart() {
        let request = SimulateRequest::from_params(&params(&[("slope", "24"), ("duration", "3")])).unwrap();
        assert_eq!(request.scaling_spread, None);
        let walks = request.walks().unwrap();
        assert!(walks.scaling_spread);
        let Answer::One(answer) = walks.respond().unwrap() else { panic!("one slope, one answer") };
        let spread = answer.scaling_spread.as_ref().expect("on by default for one slope");
        let own: Vec<SimSummary> = SCALINGS
            .iter()
            .map(|&s| {
                simulate(&walks.scenario, walks.slopes[0], &walks.settings.with_rft_scaling(s))
                    .unwrap()
                    .summary
            })
            .collect();
        for (w, o) in spread.walks.iter().zip(&own) {
            assert_eq!(
                (w.rft_scaling, w.speed_m_s, w.regime, w.t1_s),
                (o.rft_scaling, o.speed_m_s, o.regime, o.t1_s)
            );
            assert!(spread.min_speed_m_s <= o.speed_m_s && o.speed_m_s <= spread.max_speed_m_s);
        }
        assert!(own.iter().any(|o| o.speed_m_s == spread.min_speed_m_s));
        assert!(own.iter().any(|o| o.speed_m_s == spread.max_speed_m_s));
        assert_eq!(spread.range_m_s, spread.max_speed_m_s - spread.min_speed_m_s);
        // The asked walk (the default, motion) is the spread's first, not walked twice.
        assert_eq!(answer.summary.speed_m_s, own[0].speed_m_s);
        assert_eq!(own[0].regime, Regime::Slippage);
        assert_eq!(own[2].regime, Regime::Success);
        assert!(spread.min_speed_m_s < 0.0 && spread.max_speed_m_s > 0.0);
        assert!(!spread.regimes_agree);
        let json = serde_json::to_value(&*answer).unwrap();
        assert!(json["speed_m_s"].is_number() && json["scaling_spread"]["regimes_agree"] == false);
        assert_eq!(json["scaling_spread"]["walks"][2]["rft_scaling"], "components");
    }

    /// Level sand: every scaling succeeds (docs/simulate.md's table: 34.8, 30.5, 31.7 cm/s), so
    /// the regimes agree; a sweep leaves the spread off unless asked, and it costs three walks.
    #[test]
    fn level_sand_agrees_and_a_sweep_asks_for_the_spread() {
        let level = SimulateRequest::from_params(&params(&[("slope", "0"), ("duration", "3")])).unwrap();
        let Answer::One(answer) = level.walks().unwrap().respond().unwrap() else { panic!("one") };
        let spread = answer.scaling_spread.unwrap();
        assert!(spread.regimes_agree && spread.min_speed_m_s > 0.0, "{spread:?}");
        assert!(spread.walks.iter().all(|w| w.regime == Regime::Success));
        let sweep = |on: Option<&str>| {
            let mut p = vec![("slopes", "0,10"), ("duration", "2")];
            p.extend(on.map(|v| ("scaling-spread", v)));
            SimulateRequest::from_params(&params(&p)).unwrap().walks().unwrap()
        };
        let (off, on) = (sweep(None), sweep(Some("on")));
        assert!(!off.scaling_spread && on.scaling_spread);
        let (a, b) = (off.integration_steps().unwrap(), on.integration_steps().unwrap());
        assert!((b / a - 3.0).abs() < 1e-12, "{a} {b}");
        let Answer::Many(answers) = off.respond().unwrap() else { panic!("many") };
        assert!(answers.iter().all(|a| a.scaling_spread.is_none()));
        let e = SimulateRequest::from_params(&params(&[
            ("slope", "10"),
            ("ensemble", "2"),
            ("scaling-spread", "on"),
        ]))
        .unwrap_err();
        assert_eq!(e.field(), Some("scaling-spread"));
        let e = SimulateRequest::from_params(&params(&[("slope", "10"), ("scaling-spread", "maybe")]))
            .unwrap_err();
        assert!(e.message().contains("scaling-spread"), "{}", e.message());
    }

    /// The server's count of integration steps is the walk's own: a free body walks at T/16000
    /// by default, eight times the locked walk's T/2000 steps (docs/model.md §17).
    #[test]
    fn a_free_body_costs_eight_times_the_steps_of_a_locked_one() {
        let steps = |pitch: &str| {
            let p = params(&[
                ("slope", "10"),
                ("duration", "2"),
                ("body-pitch", pitch),
                ("scaling-spread", "off"),
            ]);
            SimulateRequest::from_params(&p).unwrap().walks().unwrap().integration_steps().unwrap()
        };
        let (locked, free) = (steps("locked"), steps("free"));
        assert!((free / locked - 8.0).abs() < 1e-9, "{locked} {free}");
        // Locked: (duration + settling) / (T / 2000), the paper's robot's T of 1 s (one stride
        // a second, 0.5 ms steps).
        let walks = SimulateRequest::from_params(&params(&[("slope", "10"), ("duration", "2")]))
            .unwrap()
            .walks()
            .unwrap();
        assert_eq!(walks.scenario.robot().stride_period(), 1.0);
        let by_hand = (2.0 + walks.settings.settle_s) / 0.5e-3;
        assert!((locked / by_hand - 1.0).abs() < 1e-9, "{locked} {by_hand}");
    }
}
