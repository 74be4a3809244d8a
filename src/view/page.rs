//! The viewer page: the scene as JSON inside one HTML file with its script and style inline
//! (`assets/view/`), so it opens from disk in any current browser with no network access.

use super::Scene;
use crate::error::Result;
use std::path::Path;

const SCRIPT: &str = include_str!("../../assets/view/viewer.js");
const STYLE: &str = include_str!("../../assets/view/viewer.css");

/// Text inside an HTML element: `&`, `<` and `>` escaped.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The whole page for `scene`.
pub fn html(scene: &Scene) -> Result<String> {
    // `</` would end the script element early: JSON allows `<\/` for it.
    let json = serde_json::to_string(scene)
        .map_err(|e| crate::Error::Domain(format!("viewer scene: {e}")))?
        .replace("</", "<\\/");
    Ok(format!(
        r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>{STYLE}</style>
</head>
<body>
<header><h1>{title}</h1><p id="subtitle">{subtitle}</p></header>
<div id="controls">
  <button id="play" type="button" title="play / pause (space)">▶ play</button>
  <label>speed <select id="speed">
    <option value="0.1">0.1×</option><option value="0.25">0.25×</option>
    <option value="0.5">0.5×</option><option value="1" selected>1× (real time)</option>
    <option value="2">2×</option><option value="5">5×</option></select></label>
  <input id="slider" type="range" min="0" max="0" value="0" step="1" aria-label="time">
  <span id="clock"></span>
</div>
<main>
  <section class="panel" id="cross-panel"><h2>Leading wheelset on its rails (seen from behind)</h2>
    <canvas id="axle" width="1000" height="110"></canvas>
    <canvas id="cross" width="1000" height="420"></canvas>
    <p class="note" id="cross-note"></p></section>
  <section class="panel" id="plan-panel"><h2>Plan view: the wagon on the track</h2>
    <canvas id="plan" width="1000" height="500"></canvas>
    <p class="note" id="plan-note"></p></section>
  <section class="panel" id="trace-panel"><h2 id="trace-title">Forces of the label wheel</h2>
    <canvas id="traces" width="1000" height="520"></canvas>
    <p class="note" id="trace-note"></p></section>
</main>
<footer>Made by railforce. Keys: space play/pause, ← → one frame, Home/End.</footer>
<script id="scene" type="application/json">{json}</script>
<script>{SCRIPT}</script>
</body>
</html>
"#,
        title = escape(&scene.title),
        subtitle = escape(&scene.subtitle),
    ))
}

/// Writes the page to `path` atomically; returns its size in bytes.
pub fn write(scene: &Scene, path: &Path) -> Result<usize> {
    let text = html(scene)?;
    crate::io::write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    Ok(text.len())
}
