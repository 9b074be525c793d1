//! The CSV layouts of results that have no serde row type of their own: the design study
//! (`design --csv`: one column per varied key, then the evaluation) and the risk map
//! (`risk --map --csv`: one row per cell, k_n-major).

use std::io::Write;
use std::path::Path;

use anyhow::{anyhow, Result};

use sandslope::design::DesignStudy;
use sandslope::risk::RiskMap;
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
    sandslope_io::files::write_output(path, |file| {
        let mut w = std::io::BufWriter::with_capacity(1 << 22, file);
        risk_map_csv(map, &mut w)
            .and_then(|_| w.flush())
            .map_err(|source| sandslope_io::WriteError { path: path.to_path_buf(), source }.into())
    })
}
