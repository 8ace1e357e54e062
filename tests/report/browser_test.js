// `cheval report` in a real browser: Debian's headless Chromium driven by playwright-core (from
// report/package-lock.json; it never downloads a browser). Simulates a drone flight with the
// project's own simulator, makes two estimates with velocity (a noisy 50 Hz copy with `cheval
// velocity`, and a drifting odometry from `cheval sim motion --estimate`) and one without, writes the report and checks in the
// browser that it loads with no console error or failed request, that every chart has data (the
// trajectories, x/y/z and roll/pitch/yaw, APE and ASE over time, the error distributions, the RPE
// box plots and series, the velocity), that the page names files by label and has no absolute
// path, that legends stay on one line, the top view is fitted to the data and can be coloured by
// error, the velocity is scaled to the motion with central differences one click away, the fit
// diagnostics are collapsed, every chart exports PNG/SVG/CSV, the table shows the embedded numbers
// and the missing velocity is said on the page; then takes a full-page screenshot and one per
// section (the figures of docs/report.md). Then the rotor page of `cheval estimate rotors --report` on
// a real flight ($CHEVAL_DATA_DIR), its four motors' charts (rotorPage).
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
    tab.on('request', (r) => { if (!/^(file|blob|data):/.test(r.url())) problems.push(`request: ${r.url()}`); });
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
      svg: b.querySelectorAll('svg path, svg rect, svg line, svg polygon').length,
    })));
    const expected = ['trajectory-top', 'trajectory-side', 'x', 'y', 'z', 'roll', 'pitch', 'yaw', 'ape', 'ase', 'ase-rotation',
      'ase-position', 'ase-velocity', 'ape-histogram', 'ape-violin', 'ase-histogram', 'ase-violin', 'rpe-box-trans',
      'rpe-box-rot', 'rpe-trans', 'rpe-rot', 'velocity'];
    check(JSON.stringify(charts.map((c) => c.id)) === JSON.stringify(expected), `the charts are ${expected.join(', ')} (got ${charts.map((c) => c.id).join(', ')})`);
    for (const c of charts) check(c.points > 0 && (c.canvas || c.svg > 10), `chart ${c.id} is drawn with data (${c.points} points, ${c.canvas ? 'canvas' : c.svg + ' SVG shapes'})`);
    const instances = await tab.evaluate(() => window.chevalReport.charts.map((c) => ({ id: c.id, uplot: !!(c.chart && c.chart.series), series: c.chart && c.chart.series ? c.chart.series.length : 0 })));
    check(instances.filter((c) => c.uplot).every((c) => c.series >= 2), 'every uPlot chart has at least one series');

    // Labels, never the machine's folders: the page does not contain the work folder.
    const html = await tab.content();
    check(!html.includes(work), `the page has no absolute path (${work} absent)`);
    const legendNames = await tab.$$eval('#chart-ape .u-legend .u-series .u-label', (l) => l.map((x) => x.textContent));
    check(JSON.stringify(legendNames.slice(1)) === JSON.stringify(['noisy_velocity.tumv', 'drifting.tumv', 'poses_only.tum']), `the legends name the estimates by file name (${legendNames})`);
    // Legend entries on one line each, with filled swatches.
    const legend = await tab.$$eval('.u-legend', (legends) => legends.flatMap((table) => [...table.querySelectorAll('.u-series th')].map((c, k) => {
      const marker = c.querySelector('.u-marker'), label = c.querySelector('.u-label');
      return { x: k === 0 && !table.closest('[data-chart^="trajectory"]'), h: label.getBoundingClientRect().height, line: parseFloat(getComputedStyle(label).lineHeight), fill: marker ? getComputedStyle(marker).backgroundColor : 'none' };
    })));
    check(legend.length > 20 && legend.every((l) => l.h <= l.line + 1), `every legend label is on one line (${legend.length} entries, tallest ${Math.max(...legend.map((l) => l.h))} px, line ${legend[0].line} px)`);
    check(legend.filter((l) => !l.x).every((l) => l.fill !== 'none' && l.fill !== 'rgba(0, 0, 0, 0)'), 'legend swatches are filled (every series but the x axis)');

    // The top view is fitted to the data: the reference spans ≥ 85 % of the plot in one direction and ≥ 50 % in the other.
    const fill = await tab.evaluate(() => {
      const u = window.chevalReport.charts.find((c) => c.id === 'trajectory-top').chart;
      const p = window.chevalReport.data.reference.path_xyz;
      const xs = p.x.map((v) => u.valToPos(v, 'x')), ys = p.y.map((v) => u.valToPos(v, 'y'));
      return [(Math.max(...xs) - Math.min(...xs)) / u.bbox.width * devicePixelRatio, (Math.max(...ys) - Math.min(...ys)) / u.bbox.height * devicePixelRatio];
    });
    check(Math.max(...fill) >= 0.85 && Math.min(...fill) >= 0.5, `the top view is fitted to the data (spans ${fill.map((f) => f.toFixed(2))})`);
    // Colour by error: the SVG of the top view has the colour map and its bar.
    await tab.click('#trajectory-controls button[data-choice="1"]');
    const colored = await tab.evaluate(() => window.chevalReport.charts.find((c) => c.id === 'trajectory-top').svg());
    check((colored.match(/<line [^>]*stroke="rgb\(/g) || []).length > 500 && colored.includes('APE (m)'), 'colour by APE draws the path in the colour map with a colour bar');
    check(colored.includes('<circle') && colored.includes('<rect x='), 'the top view has start and end markers');
    fs.mkdirSync(outputDir, { recursive: true });
    await (await tab.$('#chart-trajectory-top')).screenshot({ path: path.join(outputDir, 'report_top_view_error.png') });
    await tab.click('#trajectory-controls button[data-choice="none"]');

    // The ASE rotation part in degrees.
    const rotation = await tab.evaluate(() => {
      const e = window.chevalReport.data.estimates[0];
      return { deg: !!e.ase_series.rotation_deg, old: 'rotation' in e.ase_series, title: document.querySelector('#chart-ase-rotation h3').textContent };
    });
    check(rotation.deg && !rotation.old && rotation.title.includes('°'), `the ASE rotation part is in degrees (${rotation.title})`);

    // Velocity: central differences hidden by default, one click shows them; the range is the motion's.
    const velocity = await tab.evaluate(() => {
      const c = window.chevalReport.charts.find((x) => x.id === 'velocity');
      const central = c.chart.series.findIndex((s) => s.label === 'reference, central diff.');
      const speeds = window.chevalReport.data.reference_velocity.chebyshev.speed;
      return { shown: c.chart.series[central].show, top: c.chart.scales.y.max, motion: Math.max(...speeds) };
    });
    check(velocity.shown === false, 'central differences are hidden by default');
    check(velocity.top <= velocity.motion * 1.3, `the velocity chart is scaled to the motion (y max ${velocity.top.toFixed(2)}, speed max ${velocity.motion.toFixed(2)})`);
    await tab.click('#toggle-central');
    const centralShown = await tab.evaluate(() => {
      const c = window.chevalReport.charts.find((x) => x.id === 'velocity');
      return c.chart.series.find((s) => s.label === 'reference, central diff.').show;
    });
    check(centralShown === true, 'one click shows the central differences');
    await tab.click('#toggle-central');

    // RPE: a box per estimate and distance; the buttons redraw the series over time.
    const rpe = await tab.evaluate(() => ({ distances: window.chevalReport.data.rpe_distances, boxes: document.querySelectorAll('#chart-rpe-box-trans svg rect[fill-opacity]').length }));
    check(rpe.distances.length === 5 && rpe.boxes === 5 * 3, `the RPE box plot has 5 distances x 3 estimates (${rpe.boxes} boxes)`);
    await tab.click(`#rpe button[data-choice="${rpe.distances[2]}"]`);
    const rpeTitle = await tab.$eval('#chart-rpe-trans h3', (h) => h.textContent);
    check(rpeTitle.includes(String(rpe.distances[2])) && (await tab.$eval('#chart-rpe-trans', (b) => Number(b.dataset.points))) > 0, `the RPE over time is redrawn at another distance (${rpeTitle})`);

    // Fit diagnostics: collapsed, drawn when opened.
    check(await tab.$eval('#fit-section', (d) => !d.open) && (await tab.$$('#chart-fit-degrees')).length === 0, 'the fit diagnostics are collapsed and not drawn');
    await tab.click('#fit-section summary');
    await tab.waitForSelector('#chart-fit-coefficients[data-points]');
    const fitPoints = await tab.$$eval('#chart-fit-degrees, #chart-fit-residual, #chart-fit-coefficients', (b) => b.map((x) => Number(x.dataset.points)));
    check(fitPoints.length === 3 && fitPoints.every((n) => n > 0), `opened, the fit charts (degrees, residual against the noise, coefficients) are drawn (${fitPoints})`);

    // Every chart exports PNG, SVG and CSV; the files are what they say.
    const exportable = await tab.$$eval('.chart', (boxes) => boxes.every((b) => ['png', 'svg', 'csv'].every((k) => b.querySelector(`button[data-export="${k}"]`))));
    check(exportable, 'every chart has PNG, SVG and CSV buttons');
    async function exported(chart, kind) {
      const [download] = await Promise.all([tab.waitForEvent('download'), tab.click(`#chart-${chart} button[data-export="${kind}"]`)]);
      return { name: download.suggestedFilename(), bytes: fs.readFileSync(await download.path()) };
    }
    // The buttons download the files (one chart, the three kinds); every chart's exports are then
    // made by the same functions the buttons call, in the page.
    const downloads = {};
    for (const kind of ['svg', 'csv', 'png']) downloads[kind] = await exported('ape', kind);
    check(downloads.svg.name === 'ape.svg' && downloads.svg.bytes.toString().startsWith('<svg'), `the SVG button downloads ape.svg (${downloads.svg.bytes.length} bytes)`);
    check(downloads.csv.name === 'ape.csv' && downloads.csv.bytes.toString().startsWith('time (s),'), `the CSV button downloads ape.csv (${downloads.csv.bytes.length} bytes)`);
    check(downloads.png.name === 'ape.png' && downloads.png.bytes.subarray(1, 4).toString() === 'PNG', `the PNG button downloads ape.png (${downloads.png.bytes.length} bytes)`);
    const exports = await tab.evaluate(async () => {
      const out = [];
      for (const c of window.chevalReport.charts) {
        const svg = c.svg(), csv = c.csv().trim().split('\n');
        const png = await ChevalCharts.pngOf(svg);
        const head = new Uint8Array(await png.slice(0, 4).arrayBuffer());
        out.push({ id: c.id, svg: svg.startsWith('<svg') && /<(path|rect|line)/.test(svg) && svg.endsWith('</svg>'), svgBytes: svg.length,
          csvLines: csv.length, columns: csv[0].split(',').length, png: String.fromCharCode(...head.slice(1, 4)) === 'PNG', pngBytes: png.size });
      }
      return out;
    });
    check(exports.length === expected.length + 3, `every chart exports (${exports.length} charts with the fit diagnostics)`);
    for (const e of exports) {
      check(e.svg && e.csvLines >= 3 && e.png && e.pngBytes > 3000, `${e.id}: SVG with shapes (${e.svgBytes} B), CSV ${e.csvLines} lines x ${e.columns} columns, PNG ${e.pngBytes} B`);
    }

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
    await tab.click('#velocity-controls button[data-choice="vz"]');
    const vz = await tab.$eval('#chart-velocity', (b) => Number(b.dataset.points));
    check(vz > 0, `the velocity chart redrawn for vz has data (${vz} points)`);
    await tab.click('#velocity-controls button[data-choice="speed"]');

    fs.mkdirSync(outputDir, { recursive: true });
    const screenshot = path.join(outputDir, 'report.png');
    await tab.screenshot({ path: screenshot, fullPage: true });
    const size = fs.statSync(screenshot).size;
    check(size > 50000, `screenshot ${screenshot} written (${size} bytes)`);
    // One screenshot per section, the figures of docs/report.md.
    for (const [name, selector] of [['report_top', 'header'], ['report_trajectories', '#trajectories'], ['report_pose', '#pose-charts'],
      ['report_errors', '#errors'], ['report_distributions', '#distributions'], ['report_rpe', '#rpe'], ['report_velocity', '#velocity']]) {
      await (await tab.$(selector)).screenshot({ path: path.join(outputDir, name + '.png') });
    }
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

    await rotorPage(tab, problems);
  } finally {
    await context.close();
  }
}

// The page of `cheval estimate rotors --report` on a real Crazyflie flight ($CHEVAL_DATA_DIR; absent:
// skipped, a failure in CI): the four motors' charts drawn with three series each, the non-scored
// spans shaded, the table equal to the errors of --json, every chart exporting.
async function rotorPage(tab, problems) {
  const flight = path.join(process.env.CHEVAL_DATA_DIR || '', 'crazyflie_brushless_idsia', 'square_20251017_run1.csv');
  if (!fs.existsSync(flight)) {
    check(process.env.CI !== 'true', `the rotor page: ${flight} not found (skipped outside CI)`);
    return;
  }
  const vehicle = path.join(__dirname, '..', '..', 'data', 'vehicles', 'crazyflie21_brushless.json');
  run('estimate', 'rotors', '--data', flight, '--vehicle', vehicle, '--json', 'rotors.json', '--report', 'rotors.html');
  const json = JSON.parse(fs.readFileSync(path.join(work, 'rotors.json'), 'utf8'));
  problems.length = 0;
  await tab.goto('file://' + path.join(work, 'rotors.html'));
  await tab.waitForSelector('body[data-ready], body[data-error]', { timeout: 30000 });
  const error = await tab.getAttribute('body', 'data-error');
  check(error === null, `the rotor page's script ran without an exception${error ? ': ' + error : ''}`);
  check(problems.length === 0, `the rotor page: no console error or warning, no request${problems.length ? ': ' + problems.join('; ') : ''}`);
  const html = await tab.content();
  check(!html.includes(process.env.CHEVAL_DATA_DIR) && !html.includes(work), 'the rotor page has no absolute path');
  const charts = await tab.evaluate(() => window.chevalReport.charts.map((c) => ({
    id: c.id, points: c.points, canvas: !!c.box.querySelector('canvas'),
    series: c.chart.series.slice(1).map((s) => s.label), drawn: c.chart.data.slice(1).map((y) => y.filter((v) => v !== null).length),
  })));
  const ids = ['rotor-m1', 'rotor-m2', 'rotor-m3', 'rotor-m4'];
  check(JSON.stringify(charts.map((c) => c.id)) === JSON.stringify(ids), `the rotor page's charts are ${ids.join(', ')} (got ${charts.map((c) => c.id).join(', ')})`);
  for (const c of charts) {
    check(c.canvas && c.points > 0 && JSON.stringify(c.series) === JSON.stringify(['measured', 'cheval', 'flatness baseline']) && c.drawn.every((n) => n > 100),
      `chart ${c.id} draws measured, cheval and the baseline (${c.drawn.join(', ')} points)`);
  }
  const data = await tab.evaluate(() => window.chevalReport.data);
  check(data.motors.every((m) => m.series.t.length <= data.max_points && m.series.n === data.samples),
    `each motor's series has at most ${data.max_points} points of ${data.samples} samples (${data.motors.map((m) => m.series.t.length)})`);
  const shown = await tab.$$eval('#table tbody tr', (rows) => rows.map((r) => [...r.querySelectorAll('td[data-key]')].map((c) => [c.dataset.key, c.textContent])));
  const expectedTable = json.rotor_error_percent.map((p, m) => [['error.rpm', json.rotor_error_rpm[m].toFixed(1)], ['error.percent', p.toFixed(3)],
    ['baseline.rpm', json.flatness_error_rpm[m].toFixed(1)], ['baseline.percent', json.flatness_error_percent[m].toFixed(3)]]);
  check(JSON.stringify(shown) === JSON.stringify(expectedTable), `the rotor table shows the errors of --json (${JSON.stringify(shown)})`);
  const svg = await tab.evaluate(() => window.chevalReport.charts[0].svg());
  check(data.unscored.length > 0 && (svg.match(/fill-opacity="0.15"/g) || []).length === data.unscored.length,
    `the ${data.unscored.length} non-scored span(s) are shaded in the exported SVG`);
  const exports = await tab.evaluate(async () => Promise.all(window.chevalReport.charts.map(async (c) => {
    const png = await ChevalCharts.pngOf(c.svg());
    return { id: c.id, svg: c.svg().split('<path').length - 1, csv: c.csv().trim().split('\n').length, png: png.size };
  })));
  for (const e of exports) check(e.svg === 3 && e.csv > 100 && e.png > 3000, `${e.id} exports: SVG ${e.svg} lines, CSV ${e.csv} lines, PNG ${e.png} B`);
  await tab.screenshot({ path: path.join(outputDir, 'rotors.png'), fullPage: true });
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
