//! The report page's stride-simulator table fits a 1000 px window (issue 41): a fixed layout
//! at the page's width, nine columns, no row painted as a disagreement, and every cell short,
//! the why of each row in a collapsible note.

use crate::common;

/// The text of `html` with its tags removed.
fn text(html: &str) -> String {
    let mut out = String::new();
    let mut in_tag = false;
    for c in html.chars() {
        match c {
            '<' => in_tag = true,
            '>' => in_tag = false,
            c if !in_tag => out.push(c),
            _ => {}
        }
    }
    out
}

#[test]
fn the_simulator_table_fits_the_page() {
    // The default report, made once for the tests that read it.
    let out = &common::default_report().dir;
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    // Its style: laid out at the page's width, not at its content's.
    assert!(page.contains("table.sim{table-layout:fixed;width:100%"), "no fixed layout for the table");
    let start = page.find("<h2 id=\"simulator-table\"").expect("the simulator section");
    let section = &page[start..];
    let table = &section[section.find("<table class=\"sim\">").expect("table.sim")..];
    let table = &table[..table.find("</table>").unwrap()];
    let rows: Vec<&str> = table.split("<tr").skip(1).collect();
    assert_eq!(rows[0].matches("<th").count(), 9, "{}", rows[0]);
    // The paper's slopes 0 to 24 deg, as report.json lists them.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(rows.len() - 1, json["simulator"].as_array().unwrap().len());
    for row in &rows[1..] {
        // No row painted pink: the verdict is the last cell's text.
        assert!(row.starts_with('>'), "a row with a class: <tr{row}");
        let cells: Vec<&str> = row.split("<td").skip(1).collect();
        assert_eq!(cells.len(), 9, "{row}");
        for cell in cells {
            // What shows before a note is opened: the cell without its note's body.
            let shown = match (cell.find("</summary>"), cell.find("</details>")) {
                (Some(a), Some(_)) => &cell[..a],
                _ => cell,
            };
            let shown = text(&format!("<td{shown}"));
            assert!(shown.chars().count() <= 36, "a long cell: {shown:?}");
        }
        assert!(row.contains("<details><summary>"), "{row}");
    }
}
