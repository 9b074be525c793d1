//! The file layouts of results that have no serde row type of their own: the design study
//! (`design --csv`: one column per varied key, then the evaluation), the risk map
//! (`risk --map --csv`: one row per cell, k_n-major; `--npy`: its arrays) and the phase
//! diagrams (`phase --csv`: one row per cell of every panel; `--npy`: its arrays).

use std::io::Write;
use std::path::Path;

use anyhow::{anyhow, Result};

use sandslope::design::DesignStudy;
use sandslope::risk::RiskMap;
use sandslope::{PhasePanel, Regime};
use sandslope_io::grid_csv::{push_f64, write_rows};

/// The design study as CSV text: a header of the varied keys' names followed by `valid,
/// invalid_reason, safe_slope_deg, safe_limit, speed_m_s, p_fail, regime, k_s_margin,
/// pareto`, then one row per design in the study's order. Absent values are empty fields;
/// numbers are written as Rust's shortest round-trip form.
pub fn design_csv(study: &DesignStudy) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = study.keys.iter().map(|k| k.name().to_string()).collect();
    header.extend(
        [
            "valid",
            "invalid_reason",
            "safe_slope_deg",
            "safe_limit",
            "speed_m_s",
            "p_fail",
            "regime",
            "k_s_margin",
            "pareto",
        ]
        .map(String::from),
    );
    w.write_record(&header)?;
    let opt = |x: Option<f64>| x.map(|v| format!("{v}")).unwrap_or_default();
    for d in &study.designs {
        let mut row: Vec<String> = d.params.iter().map(|v| format!("{v}")).collect();
        match &d.outcome {
            Ok(p) => row.extend([
                true.to_string(),
                String::new(),
                opt(p.safe_slope_deg),
                p.safe_limit.kind().to_string(),
                opt(p.speed_m_s),
                opt(Some(p.p_fail)),
                p.regime.name().to_string(),
                opt(p.k_s_margin),
                d.pareto.to_string(),
            ]),
            Err(reason) => row.extend([
                false.to_string(),
                reason.clone(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                String::new(),
                d.pareto.to_string(),
            ]),
        }
        w.write_record(&row)?;
    }
    Ok(String::from_utf8(w.into_inner().map_err(|e| anyhow!("{e}"))?)?)
}

/// The header of [`risk_map_csv`].
pub const RISK_MAP_CSV_HEADER: &str = "k_n,k_s,p_fail,p_not_success";

/// Every cell of `map`, one row each, k_n-major: `k_n,k_s,p_fail,p_not_success`, numbers in
/// their shortest round-trip form (rows formatted in parallel, written in order).
pub fn risk_map_csv(map: &RiskMap, out: &mut dyn Write) -> std::io::Result<()> {
    let (k_n, k_s) = (map.k_n_axis.values(), map.k_s_axis.values());
    let ny = k_s.len();
    write_rows(out, RISK_MAP_CSV_HEADER, k_n.len() * ny, &|c, buf| {
        let (i, j) = (c / ny, c % ny);
        for (k, v) in
            [k_n[i], k_s[j], map.p_fail_at(i, j), map.p_not_success_at(i, j)].into_iter().enumerate()
        {
            if k > 0 {
                buf.push(b',');
            }
            push_f64(buf, v);
        }
    })
}

/// [`risk_map_csv`] into the file `path` through the one output writer (nothing is left
/// behind on failure; a write error names the file).
pub fn write_risk_map_csv(path: &Path, map: &RiskMap) -> Result<()> {
    sandslope_files::write_output(path, |file| {
        let mut w = std::io::BufWriter::with_capacity(1 << 22, file);
        risk_map_csv(map, &mut w)
            .and_then(|_| w.flush())
            .map_err(|source| sandslope_files::WriteError { path: path.to_path_buf(), source }.into())
    })
}

/// `phase --csv`: writes every cell of every panel, atomically, formatted in parallel
/// (`sandslope_io::grid_csv`), one row per cell: `k_n,k_s,slope_deg,mass_kg,regime,step_m` (step empty
/// where the leg never anchors; no step column with `regime_only`).
///
/// Each axis value is formatted once per panel, not once per row: `phase --csv` on a 4096 x
/// 4096 grid spent two thirds of its formatting on `k_n` and `k_s` (two ryu calls a row
/// against one for the step), docs/phase-and-risk.md gives the times.
pub fn write_phase_csv(path: &Path, panels: &[PhasePanel], regime_only: bool) -> Result<()> {
    use sandslope_io::grid_csv::write_rows_file;
    let per_panel: Vec<usize> = panels.iter().map(|p| p.map.k_n().len() * p.map.k_s().len()).collect();
    let starts: Vec<usize> = per_panel
        .iter()
        .scan(0, |a, &n| {
            let s = *a;
            *a += n;
            Some(s)
        })
        .collect();
    let total = per_panel.iter().sum();
    // Per panel, the constant text ",slope,mass,".
    let mids: Vec<Vec<u8>> = panels
        .iter()
        .map(|p| {
            let mut b = vec![b','];
            push_f64(&mut b, p.slope_deg);
            b.push(b',');
            push_f64(&mut b, p.mass_kg);
            b.push(b',');
            b
        })
        .collect();
    // Per panel, every axis value's text: "k_n," per column and "k_s" per row.
    let texts = |values: &[f64], comma: bool| -> Vec<Vec<u8>> {
        values
            .iter()
            .map(|&v| {
                let mut b = Vec::with_capacity(24);
                push_f64(&mut b, v);
                if comma {
                    b.push(b',');
                }
                b
            })
            .collect()
    };
    let k_n_texts: Vec<Vec<Vec<u8>>> = panels.iter().map(|p| texts(p.map.k_n(), true)).collect();
    let k_s_texts: Vec<Vec<Vec<u8>>> = panels.iter().map(|p| texts(p.map.k_s(), false)).collect();
    // The regime names with the separator that follows them.
    let names: Vec<Vec<u8>> = Regime::ALL
        .iter()
        .map(|r| {
            let mut b = r.name().as_bytes().to_vec();
            if !regime_only {
                b.push(b',');
            }
            b
        })
        .collect();
    let header = if regime_only {
        "k_n,k_s,slope_deg,mass_kg,regime"
    } else {
        "k_n,k_s,slope_deg,mass_kg,regime,step_m"
    };
    write_rows_file(path, header, total, &|c, buf| {
        let k = starts.partition_point(|&s| s <= c) - 1;
        let (p, cell) = (&panels[k], c - starts[k]);
        let nx = p.map.k_n().len();
        let (i, j) = (cell % nx, cell / nx);
        buf.extend_from_slice(&k_n_texts[k][i]);
        buf.extend_from_slice(&k_s_texts[k][j]);
        buf.extend_from_slice(&mids[k]);
        buf.extend_from_slice(&names[p.map.regime(i, j) as usize]);
        if !regime_only {
            if let Some(step) = p.map.step(i, j) {
                push_f64(buf, step);
            }
        }
    })
}

/// Writes the maps as NumPy arrays into `dir` (checked before any work): `regime.npy` (and
/// `step_m.npy`) of shape (masses, slopes, k_s, k_n), and the four axes.
pub fn write_phase_npy(
    dir: &Path,
    panels: &[PhasePanel],
    masses: &[f64],
    slopes: &[f64],
    regime_only: bool,
) -> Result<()> {
    use rayon::prelude::*;
    use sandslope_io::npy::{write_npy_dir, NpyData};
    let first = &panels[0].map;
    let (k_n, k_s) = (first.k_n(), first.k_s());
    let (nx, cells) = (k_n.len(), k_n.len() * k_s.len());
    let n = cells * panels.len();
    let mut regime: Vec<i8> = Vec::with_capacity(n);
    let mut step: Vec<f64> = Vec::with_capacity(if regime_only { 0 } else { n });
    // One pass per row over both arrays (PhaseMap::write_row), rows in parallel.
    let map_row = |r: usize| (&panels[r / k_s.len()].map, r % k_s.len());
    let codes = regime.spare_capacity_mut()[..n].par_chunks_mut(nx);
    if regime_only {
        codes.enumerate().for_each(|(r, codes)| {
            let (map, j) = map_row(r);
            map.write_row(j, codes, None);
        });
    } else {
        codes.zip(step.spare_capacity_mut()[..n].par_chunks_mut(nx)).enumerate().for_each(
            |(r, (codes, steps))| {
                let (map, j) = map_row(r);
                map.write_row(j, codes, Some(steps));
            },
        );
    }
    // SAFETY: `write_row` writes every element of each row of `nx` codes (and steps); the rows
    // cover the first `n` elements, and `n` is within both capacities.
    unsafe {
        regime.set_len(n);
        if !regime_only {
            step.set_len(n);
        }
    }
    let shape = vec![masses.len(), slopes.len(), k_s.len(), k_n.len()];
    let mut files = vec![("regime.npy", shape.clone(), NpyData::I8(&regime))];
    if !regime_only {
        files.push(("step_m.npy", shape, NpyData::F64(&step)));
    }
    files.extend([
        ("k_n.npy", vec![k_n.len()], NpyData::F64(k_n)),
        ("k_s.npy", vec![k_s.len()], NpyData::F64(k_s)),
        ("slope_deg.npy", vec![slopes.len()], NpyData::F64(slopes)),
        ("mass_kg.npy", vec![masses.len()], NpyData::F64(masses)),
    ]);
    write_npy_dir(dir, &files)
}

/// `risk --map --npy`: the map as NumPy arrays into `dir`: `p_fail.npy` and
/// `p_not_success.npy` of shape (k_s, k_n), and the two axes.
pub fn write_risk_map_npy(dir: &Path, map: &RiskMap) -> Result<()> {
    use sandslope_io::npy::{write_npy_dir, NpyData};
    let (k_n, k_s) = (map.k_n_axis.values(), map.k_s_axis.values());
    let shape = vec![k_s.len(), k_n.len()];
    write_npy_dir(
        dir,
        &[
            ("p_fail.npy", shape.clone(), NpyData::F64(&map.p_fail)),
            ("p_not_success.npy", shape, NpyData::F64(&map.p_not_success)),
            ("k_n.npy", vec![k_n.len()], NpyData::F64(&k_n)),
            ("k_s.npy", vec![k_s.len()], NpyData::F64(&k_s)),
        ],
    )
}
