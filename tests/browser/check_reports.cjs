// Opens robomill reports in headless Chromium (playwright-core driving the
// system's chromium) as a user would, and checks each one:
//  - no console error, no uncaught page error, no request beyond file:/data:
//    (a report must work offline);
//  - every figure rendered by Plotly, with at least one trace holding data;
//  - every 2-D figure's y axes and at least one x axis titled (units), and
//    every 3-D scene's axes titled;
//  - the key-results table present;
//  - every button of a figure's menus (updatemenus: the facet of a map, the
//    colouring of the tool path) applied without error, its data intact;
//  - what particular reports must show (`expected`: the toolpath page's
//    figures and tables).
// Saves a full-page PNG per report. Exit status 1 on any failure.
//
// usage: node check_reports.cjs NODE_MODULES CHROMIUM SHOT_DIR NAME=REPORT.html...
'use strict';
const path = require('path');
const fs = require('fs');

const [nodeModules, chromiumPath, shotDir, ...reports] = process.argv.slice(2);
const { chromium } = require(path.resolve(nodeModules, 'playwright-core'));

// Beyond the common checks, by report name: figure titles and table
// captions (parts) that must be on the page.
const expected = {
  toolpath: {
    figures: ['Tool path', 'Engagement and loads over time', 'Final stock, height map',
              'Final stock, 3-D view'],
    tables: ['moves with the largest cutting force', 'Warnings of the analysis'],
  },
};

function hasData(trace) {
  const arrays = [];
  for (const key of ['x', 'y', 'z']) if (Array.isArray(trace[key])) arrays.push(trace[key]);
  const finite = (v) => (Array.isArray(v) ? v.some(finite) : typeof v === 'number' && Number.isFinite(v));
  if (trace.type === 'heatmap' || trace.type === 'surface' || trace.type === 'contour')
    return Array.isArray(trace.z) && finite(trace.z);
  return Array.isArray(trace.y) && trace.y.length > 0 && finite(trace.y) &&
         (!Array.isArray(trace.x) || trace.x.length > 0);
}

// Runs in the page: applies every menu button of every figure, as a click
// would (Plotly's own method and arguments), then the first again; returns
// the errors and the figures whose visible traces lost their data.
async function pressMenus() {
  const problems = [];
  for (const div of document.querySelectorAll('div.plot')) {
    const menus = (div.layout && div.layout.updatemenus) || [];
    for (const menu of menus) {
      const buttons = menu.buttons || [];
      for (const b of [...buttons, buttons[0]]) {
        if (!b || !b.method || !Plotly[b.method]) continue;
        try {
          await Plotly[b.method](div, ...(b.args || []));
        } catch (e) {
          problems.push(`figure "${div.dataset.title}": menu "${b.label}": ${e.message}`);
        }
      }
    }
  }
  return problems;
}

// Runs in the page: what each figure holds.
function inspectFigures() {
  const out = [];
  for (const div of document.querySelectorAll('div.plot')) {
    const layout = div.layout || {};
    const axes = {};
    for (const key of Object.keys(div._fullLayout || {})) {
      if (/^[xy]axis\d*$/.test(key)) {
        const a = div._fullLayout[key];
        axes[key] = (a.title && a.title.text) || '';
      }
    }
    const scenes = [];
    for (const key of Object.keys(div._fullLayout || {})) {
      if (/^scene\d*$/.test(key)) {
        const s = div._fullLayout[key];
        scenes.push(['xaxis', 'yaxis', 'zaxis'].map((k) => (s[k].title && s[k].title.text) || ''));
      }
    }
    out.push({
      id: div.id,
      title: div.dataset.title,
      rendered: !!div.querySelector('.main-svg'),
      traces: (div.data || []).map((t) => ({ type: t.type || 'scatter', x: t.x, y: t.y, z: t.z, visible: t.visible })),
      axes,
      scenes,
      hasLayout: !!layout,
    });
  }
  return out;
}

(async () => {
  fs.mkdirSync(shotDir, { recursive: true });
  const browser = await chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage'],
  });
  let failures = 0;
  // One page serves every report, each opened through the same URL (a link,
  // SHOTS/.current, to the report's folder): the renderer then finds its V8
  // compilation of the embedded plotly.js (the same 4.8 MB script in every
  // report, cached by source and URL) instead of compiling it again, about
  // 2.5 s of CI's CPU per report. Each report is still a new document loaded
  // from its own folder; the listeners report into the current one's problems.
  const current = path.join(shotDir, '.current');
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  let problems = [];
  page.on('console', (m) => { if (m.type() === 'error') problems.push('console error: ' + m.text()); });
  page.on('pageerror', (e) => problems.push('page error: ' + e.message));
  page.on('request', (r) => {
    const url = r.url();
    if (!url.startsWith('file:') && !url.startsWith('data:') && !url.startsWith('blob:'))
      problems.push('network request (a report must work offline): ' + url);
  });
  for (const item of reports) {
    const eq = item.indexOf('=');
    const name = item.slice(0, eq);
    const file = path.resolve(item.slice(eq + 1));
    problems = [];
    await page.goto('about:blank');
    await page.setViewportSize({ width: 1280, height: 900 });
    fs.rmSync(current, { force: true });
    fs.symlinkSync(path.dirname(file), current);
    try {
      await page.goto('file://' + path.join(current, path.basename(file)),
                      { waitUntil: 'load', timeout: 60000 });
      await page.waitForFunction(
        () => [...document.querySelectorAll('div.plot')].every((d) => d.querySelector('.main-svg')),
        null, { timeout: 60000 });
      const figures = await page.evaluate(inspectFigures);
      if (figures.length === 0) problems.push('no figure');
      for (const f of figures) {
        const label = `figure "${f.title}"`;
        if (!f.rendered) problems.push(`${label}: not rendered`);
        if (f.traces.length === 0) problems.push(`${label}: no data traces`);
        else if (!f.traces.some(hasData)) problems.push(`${label}: every trace is empty`);
        for (const t of f.traces)
          if (t.visible !== false && !hasData(t) && t.type !== 'bar')
            problems.push(`${label}: an empty ${t.type} trace`);
        const is3d = f.scenes.length > 0;
        if (is3d) {
          for (const s of f.scenes) if (s.some((t) => !t)) problems.push(`${label}: untitled 3-D axis`);
        } else {
          const ys = Object.keys(f.axes).filter((k) => k.startsWith('y'));
          const xs = Object.keys(f.axes).filter((k) => k.startsWith('x'));
          for (const y of ys) if (!f.axes[y]) problems.push(`${label}: ${y} has no title`);
          if (!xs.some((x) => f.axes[x])) problems.push(`${label}: no titled x axis`);
        }
      }
      const results = await page.$$eval('table.results tr', (rows) => rows.length);
      if (results < 2) problems.push('key-results table empty');
      const want = expected[name];
      if (want) {
        for (const title of want.figures || [])
          if (!figures.some((f) => f.title === title)) problems.push(`no figure "${title}"`);
        const captions = await page.$$eval('table.data', (tables) => tables.map((t) => ({
          caption: t.caption ? t.caption.textContent : '',
          rows: t.tBodies.length ? t.tBodies[0].rows.length : 0,
        })));
        for (const part of want.tables || [])
          if (!captions.some((t) => t.caption.includes(part) && t.rows > 0))
            problems.push(`no table "…${part}…" with rows`);
      }
      problems.push(...(await page.evaluate(pressMenus)));
      for (const f of await page.evaluate(inspectFigures))
        for (const t of f.traces)
          if (t.visible !== false && t.visible !== 'legendonly' && !hasData(t) && t.type !== 'bar')
            problems.push(`figure "${f.title}": an empty ${t.type} trace after its menus`);
      const shot = path.join(shotDir, name + '.png');
      await page.screenshot({ path: shot, fullPage: true });
      console.log(`${problems.length ? 'FAIL' : 'ok  '} ${name}: ${figures.length} figures → ${shot}`);
    } catch (e) {
      problems.push('could not check: ' + e.message);
    }
    for (const p of problems) console.log(`     ${name}: ${p}`);
    if (problems.length) failures++;
  }
  await page.close();
  await browser.close();
  fs.rmSync(current, { force: true });
  if (failures) {
    console.log(`${failures} of ${reports.length} reports failed`);
    process.exit(1);
  }
  console.log(`all ${reports.length} reports passed`);
})().catch((e) => { console.error(e); process.exit(1); });
