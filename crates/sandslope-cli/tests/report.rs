//! `sandslope report`: the page is self-contained, carries every figure id of the paper and the
//! documented report.json; a real browser (headless Chromium, when installed) renders it to a
//! screenshot that is not blank.

use assert_cmd::Command;
use std::path::Path;

fn sandslope() -> Command {
    Command::cargo_bin("sandslope").unwrap()
}

/// The page's figure elements; fig6 holds the panels fig6a-d (anchored inside it).
const PAGE_IDS: [&str; 8] = ["fig3a", "fig4d", "fig4h", "fig5b", "fig5c", "fig6", "risk", "calibration"];
/// The ids of report.json, the paper's figure numbers.
const IDS: [&str; 11] =
    ["fig3a", "fig4d", "fig4h", "fig5b", "fig5c", "fig6a", "fig6b", "fig6c", "fig6d", "risk", "calibration"];

fn make_report(dir: &Path) -> (String, serde_json::Value) {
    sandslope().args(["report", "--out"]).arg(dir).assert().success();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let json = serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    (html, json)
}

#[test]
fn report_page_is_self_contained_and_json_has_the_documented_shape() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let (html, v) = make_report(&out);
    // Every figure inline, by the paper's ids; nothing fetched at view time.
    for id in PAGE_IDS {
        assert!(html.contains(&format!("<figure id=\"{id}\">")), "figure {id} missing");
    }
    for id in ["fig6a", "fig6b", "fig6c", "fig6d"] {
        assert!(html.contains(&format!("<span id=\"{id}\"></span>")), "anchor {id} missing");
    }
    // Inline SVG, one per figure element.
    assert_eq!(html.matches("<svg").count(), PAGE_IDS.len());
    for remote in ["src=\"http", "href=\"http", "<script", "@import", "url(http"] {
        assert!(!html.contains(remote), "page references {remote}");
    }
    assert!(html.contains("Where the model and the paper disagree"));
    let ids: Vec<&str> = v["figures"].as_array().unwrap().iter().map(|f| f["id"].as_str().unwrap()).collect();
    assert_eq!(ids, IDS);
    // The paper's five speeds (docs/model.md §12), each with the model beside it.
    let speeds = v["speeds"].as_array().unwrap();
    let slopes: Vec<f64> = speeds.iter().map(|s| s["slope_deg"].as_f64().unwrap()).collect();
    assert_eq!(slopes, [0.0, 10.0, 15.0, 20.0, 24.0]);
    assert_eq!(speeds[3]["observed_m_s"], 0.0498);
    for s in speeds {
        for key in ["observed_m_s", "observed_sd_m_s", "model_m_s"] {
            assert!(s.get(key).is_some(), "{key} missing in {s}");
        }
    }
    // The default report's calibration is the built-in terrain's (docs/calibration.md):
    // k_s(20)/k_s(0) = 0.463, chi^2 5.95 over 3 dof.
    let c = &v["calibration"];
    assert!((c["shear_ratio_20"]["value"].as_f64().unwrap() - 0.463).abs() < 1e-3, "{c}");
    assert_eq!(c["dof"], 3);
    assert!((c["chi_squared"].as_f64().unwrap() - 5.95).abs() < 0.01);
    // The comparison table: the 0.40 force ratio row and the Fig. 6d claim are there.
    let rows = v["paper_vs_model"].as_array().unwrap();
    assert!(rows.iter().any(|r| r["id"] == "shear_ratio_20" && r["paper_value"] == 0.4));
    assert!(rows.iter().any(|r| r["id"] == "heavy_robot_24"));
    // Every disagreement in the JSON is on the page.
    for d in v["disagreements"].as_array().unwrap() {
        let text = d.as_str().unwrap().replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
        assert!(html.contains(&text.replace('"', "&quot;")), "{text}");
    }
}

#[test]
fn report_refuses_a_file_as_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    sandslope().args(["report", "--out"]).arg(&file).assert().code(2);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

fn chromium() -> Option<String> {
    ["chromium", "chromium-browser", "google-chrome"].iter().find_map(|name| {
        let ok = std::process::Command::new(name).arg("--version").output().is_ok_and(|o| o.status.success());
        ok.then(|| name.to_string())
    })
}

/// Renders the page in headless Chromium (Debian's `chromium`) and checks the screenshot shows
/// content: many non-white pixels and many colours (a blank or broken page has neither).
/// Skips, saying so, when no Chromium is installed.
#[test]
fn report_renders_in_a_real_browser() {
    let Some(browser) = chromium() else {
        eprintln!("skipped: no chromium installed (apt-get install chromium)");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    make_report(&out);
    let profile = tempfile::tempdir().unwrap();
    let shot = dir.path().join("shot.png");
    let status = std::process::Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--hide-scrollbars",
            "--window-size=1200,3000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", out.join("index.html").display()))
        .output()
        .unwrap();
    assert!(shot.exists(), "no screenshot: {}", String::from_utf8_lossy(&status.stderr));
    if let Ok(keep) = std::env::var("SANDSLOPE_REPORT_SCREENSHOT") {
        std::fs::copy(&shot, keep).unwrap();
    }
    let decoder = png::Decoder::new(std::fs::File::open(&shot).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(channels).collect();
    let non_white = pixels.iter().filter(|p| p[..3].iter().any(|&c| c < 235)).count();
    let mut colours: Vec<[u8; 3]> = pixels.iter().map(|p| [p[0] & 0xf0, p[1] & 0xf0, p[2] & 0xf0]).collect();
    colours.sort_unstable();
    colours.dedup();
    let fraction = non_white as f64 / pixels.len() as f64;
    assert!(fraction > 0.03, "screenshot nearly blank: {fraction:.4} of pixels non-white");
    assert!(colours.len() > 20, "screenshot has only {} colours", colours.len());
}
