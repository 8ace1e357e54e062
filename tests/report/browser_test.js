// `cheval report` in a real browser: Debian's headless Chromium driven by playwright-core (from
// report/package-lock.json; it never downloads a browser). Simulates a drone flight with the
// project's own simulator, makes two estimates with velocity (a noisy 50 Hz copy with `cheval
// velocity`, and a drifting odometry from `cheval sim motion --estimate`) and one without, writes the report and checks in the
// browser that it loads with no console error or failed request, that every chart has data, that
// the table shows the embedded numbers and that the missing velocity is said on the page; then
// takes a full-page screenshot.
//
//   node browser_test.js CHEVAL_EXE NODE_MODULES OUTPUT_DIR
//
// Exit 0: passed; 1: failed; 77: skipped (no Chromium and not in CI; in CI, CI=true, a missing
// Chromium is a failure). Chromium: $CHEVAL_CHROMIUM, else /usr/bin/chromium.
'use strict';

const { execFileSync } = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');

const [cheval, nodeModules, outputDir] = process.argv.slice(2);
if (!cheval || !nodeModules || !outputDir) {
  console.error('usage: node browser_test.js CHEVAL_EXE NODE_MODULES OUTPUT_DIR');
  process.exit(1);
}
const chromium = process.env.CHEVAL_CHROMIUM || '/usr/bin/chromium';
if (!fs.existsSync(chromium)) {
  if (process.env.CI === 'true') {
    console.error(`browser_test: error: ${chromium} not found (install the Debian packages chromium and chromium-driver: scripts/install-deps.sh)`);
    process.exit(1);
  }
  console.log(`browser_test: skipped: ${chromium} not found (scripts/install-deps.sh installs it)`);
  process.exit(77);
}
const { chromium: playwright } = require(path.join(nodeModules, 'playwright-core'));

let failures = 0;
function check(condition, what) {
  if (condition) {
    console.log(`ok: ${what}`);
  } else {
    console.log(`FAILED: ${what}`);
    failures++;
  }
}

function run(...args) {
  return execFileSync(cheval, args, { cwd: work, encoding: 'utf8' });
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'cheval_report_browser_'));
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'cheval_report_chromium_'));

async function main() {
  // The reference (0.5 mm motion capture) and a simulated odometry output with drifting errors.
  run('sim', 'motion', '--kind', 'drone', '--seed', '1', '--noise', '0.0005', '--duration', '60', '-o', 'mocap.tum',
    '--estimate', 'drifting.tumv', '--estimate-drift', '0.003', '--estimate-rate', '200');
  run('sim', 'motion', '--kind', 'drone', '--seed', '1', '--noise', '0.01', '--rotation-noise', '0.003', '--duration', '60',
    '--rate', '50', '-o', 'noisy.tum');
  run('velocity', 'noisy.tum', '-o', 'noisy_velocity.tumv');
  run('sim', 'motion', '--kind', 'drone', '--seed', '1', '--noise', '0.03', '--duration', '60', '--rate', '20', '-o', 'poses_only.tum');
  const printed = run('report', 'mocap.tum', 'noisy_velocity.tumv', 'drifting.tumv', 'poses_only.tum', '-o', 'report.html');
  process.stdout.write(printed);
  const page = path.join(work, 'report.html');

  // A fresh profile (Playwright passes it as --user-data-dir).
  const context = await playwright.launchPersistentContext(profile, {
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync'],
    viewport: { width: 1400, height: 900 },
    deviceScaleFactor: 1,
  });
  try {
    const tab = await context.newPage();
    const problems = [];
    tab.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') problems.push(`console ${m.type()}: ${m.text()}`); });
    tab.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
    // A self-contained page requests nothing but itself.
    tab.on('request', (r) => { if (!r.url().startsWith('file://')) problems.push(`request: ${r.url()}`); });
    tab.on('requestfailed', (r) => problems.push(`request failed: ${r.url()}`));
    await tab.goto('file://' + page);
    await tab.waitForSelector('body[data-ready], body[data-error]', { timeout: 30000 });
    const error = await tab.getAttribute('body', 'data-error');
    check(error === null, `the page script ran without an exception${error ? ': ' + error : ''}`);
    check(problems.length === 0, `no console error or warning, no request${problems.length ? ': ' + problems.join('; ') : ''}`);

    const charts = await tab.$$eval('.chart', (boxes) => boxes.map((b) => ({
      id: b.dataset.chart,
      points: Number(b.dataset.points || 0),
      canvas: !!b.querySelector('canvas'),
    })));
    const expected = ['trajectory-top', 'trajectory-side', 'ape', 'ase', 'ase-rotation', 'ase-position', 'ase-velocity',
      'velocity', 'fit-degrees', 'fit-coefficients'];
    check(JSON.stringify(charts.map((c) => c.id)) === JSON.stringify(expected), `the charts are ${expected.join(', ')} (got ${charts.map((c) => c.id).join(', ')})`);
    for (const c of charts) check(c.points > 0 && c.canvas, `chart ${c.id} is drawn with data (${c.points} points)`);
    const instances = await tab.evaluate(() => window.chevalReport.charts.map((c) => ({ id: c.id, series: c.plot.series.length, rows: c.plot.data.length })));
    check(instances.length === expected.length && instances.every((c) => c.series >= 2), 'every chart is a uPlot instance with at least one series');

    // The drawn canvases are not blank: the trajectory's canvas has pixels of the reference's ink.
    const inked = await tab.$eval('#chart-trajectory-top canvas', (canvas) => {
      const pixels = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
      let n = 0;
      for (let i = 0; i < pixels.length; i += 4) if (pixels[i + 3] > 0) n++;
      return n;
    });
    check(inked > 1000, `the top view's canvas has ink (${inked} painted pixels)`);

    // The table shows the embedded statistics (the numbers of `cheval ape --json`, checked by report_cli_test).
    const table = await tab.evaluate(() => {
      const data = window.chevalReport.data;
      return data.estimates.map((e, i) => ({
        shown: document.querySelector(`tr[data-estimate="${i}"] td[data-key="ape.rmse"]`).textContent,
        embedded: e.ape.stats.rmse.toFixed(6),
        aseShown: e.ase ? document.querySelector(`tr[data-estimate="${i}"] td[data-key="ase.rmse"]`).textContent : null,
        aseEmbedded: e.ase ? e.ase.stats.rmse.toFixed(6) : null,
      }));
    });
    check(table.length === 3 && table.every((r) => r.shown === r.embedded && r.aseShown === r.aseEmbedded), `the table shows the embedded APE and ASE RMSE (${JSON.stringify(table)})`);
    const notes = await tab.$$eval('#notes li', (items) => items.map((i) => i.textContent));
    check(notes.some((n) => n.includes('poses_only.tum has no velocity')), 'the page says the estimate without velocity has no ASE');
    const aseNote = await tab.$eval('#chart-ase .chart-note', (n) => n.textContent);
    check(aseNote.includes('poses_only.tum'), `the ASE chart names the estimate it leaves out (${aseNote})`);

    // The velocity component buttons redraw the chart with data.
    await tab.click('#velocity-controls button[data-component="vz"]');
    const vz = await tab.$eval('#chart-velocity', (b) => Number(b.dataset.points));
    check(vz > 0, `the velocity chart redrawn for vz has data (${vz} points)`);
    await tab.click('#velocity-controls button[data-component="speed"]');

    fs.mkdirSync(outputDir, { recursive: true });
    const screenshot = path.join(outputDir, 'report.png');
    await tab.screenshot({ path: screenshot, fullPage: true });
    const size = fs.statSync(screenshot).size;
    check(size > 50000, `screenshot ${screenshot} written (${size} bytes)`);
    fs.copyFileSync(page, path.join(outputDir, 'report.html'));

    // The report of the README's demo data (scripts/demo.sh, steps 1 and 4) renders with every chart.
    run('sim', 'motion', '--kind', 'drone', '--seed', '7', '--noise', '0.0005', '--rotation-noise', '0.003', '--duration', '60',
      '--rate', '200', '-o', 'demo_mocap.txt', '--estimate', 'demo_vio_a.txt', '--estimate', 'demo_vio_b.txt',
      '--estimate-drift', '0.001', '0.004', '--quiet');
    run('report', 'demo_mocap.txt', 'demo_vio_a.txt', 'demo_vio_b.txt', '-o', 'demo_report.html');
    problems.length = 0;
    await tab.goto('file://' + path.join(work, 'demo_report.html'));
    await tab.waitForSelector('body[data-ready], body[data-error]', { timeout: 30000 });
    check(await tab.getAttribute('body', 'data-error') === null, 'the demo report\'s script ran without an exception');
    check(problems.length === 0, `the demo report: no console error or warning, no request${problems.length ? ': ' + problems.join('; ') : ''}`);
    const demoCharts = await tab.$$eval('.chart', (boxes) => boxes.map((b) => ({ id: b.dataset.chart, points: Number(b.dataset.points || 0) })));
    check(JSON.stringify(demoCharts.map((c) => c.id)) === JSON.stringify(expected), `the demo report has every chart (${demoCharts.map((c) => c.id).join(', ')})`);
    for (const c of demoCharts) check(c.points > 0, `demo report: chart ${c.id} has data (${c.points} points)`);
  } finally {
    await context.close();
  }
}

main()
  .catch((e) => {
    console.log(`FAILED: ${e.stack || e}`);
    failures++;
  })
  .finally(() => {
    fs.rmSync(work, { recursive: true, force: true });
    fs.rmSync(profile, { recursive: true, force: true });
    console.log(failures ? `browser_test: ${failures} check(s) failed` : 'browser_test: all checks passed');
    process.exit(failures ? 1 : 0);
  });
