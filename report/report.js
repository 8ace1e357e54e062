// cheval report: draws the embedded data (the JSON of the script element #cheval-data, written by
// cheval::report::BuildReport) with uPlot. Every chart's container gets data-points = the number of
// points it plots, and window.chevalReport lists the charts, so a test can tell that each has data;
// document.body gets data-ready when everything is drawn (data-error if something failed).
'use strict';

(function () {
  const data = JSON.parse(document.getElementById('cheval-data').textContent);
  const charts = [];
  const palette = ['#0969da', '#cf222e', '#1a7f37', '#8250df', '#bc4c00', '#1b7c83', '#bf3989', '#6e7781'];
  const reference = { color: '#1f2328', chebyshev: '#1f2328', central: '#8c959f', given: '#bf8700' };
  const timeLabel = data.time_axis === 's' ? 'time (s)' : 'pose index';
  const estimates = data.estimates;
  const colorOf = (i) => palette[i % palette.length];

  // Short names for legends: the fewest trailing path components that tell the estimates apart
  // (two runs are often both .../vins_result_no_loop.csv).
  const labels = (() => {
    const parts = estimates.map((e) => e.path.split('/').filter((p) => p.length));
    const longest = Math.max(...parts.map((p) => p.length));
    for (let n = 1; n < longest; n++) {
      const names = parts.map((p) => p.slice(-n).join('/'));
      if (new Set(names).size === names.length) return names;
    }
    return estimates.map((e) => e.path);
  })();

  // ---- small DOM helpers --------------------------------------------------------------------
  function el(tag, attributes, ...children) {
    const node = document.createElement(tag);
    for (const [key, value] of Object.entries(attributes || {})) {
      if (key === 'text') node.textContent = value;
      else node.setAttribute(key, value);
    }
    for (const child of children) node.append(child);
    return node;
  }
  function definitions(list, pairs) {
    for (const [term, value] of pairs) list.append(el('dt', { text: term }), el('dd', { text: value }));
  }
  function fixed(value, digits = 6) {
    return value === null || value === undefined || !Number.isFinite(value) ? '–' : value.toFixed(digits);
  }
  function countPoints(columns) {
    let n = 0;
    for (const column of columns) for (const v of column) if (v !== null && v !== undefined) n++;
    return n;
  }

  // ---- charts -------------------------------------------------------------------------------
  // A chart's box: a title, the plot, an optional note. Returns {box, plot}.
  function chartBox(parent, id, title, note) {
    const plot = el('div', { class: 'plot' });
    const box = el('div', { class: 'chart', id: 'chart-' + id, 'data-chart': id }, el('h3', { text: title }), plot);
    if (note) box.append(el('p', { class: 'chart-note', text: note }));
    parent.append(box);
    return { box, plot };
  }
  function plotWidth(target) {
    return Math.max(320, Math.floor(target.plot.getBoundingClientRect().width || 600));
  }
  function register(id, target, plot, points) {
    target.box.dataset.points = String(points);
    const entry = charts.find((c) => c.id === id);
    if (entry) {
      entry.plot.destroy();
      Object.assign(entry, { plot, points });
    } else {
      charts.push({ id, target, plot, points });
    }
  }

  // Lines over time (or another sorted x): lines = [{label, color, x, y, dash}], joined on x.
  function lineChart(target, id, xLabel, yLabel, lines, options = {}) {
    const joined = uPlot.join(lines.map((l) => [l.x, l.y]));
    const series = [{ label: xLabel, value: (u, v) => (v === null || v === undefined ? '–' : v.toFixed(3)) }];
    for (const l of lines) {
      series.push({
        label: l.label,
        stroke: l.color,
        width: l.width || 1.25,
        dash: l.dash,
        spanGaps: true,
        paths: l.stepped ? uPlot.paths.stepped({ align: 1 }) : undefined,
        points: { show: !!l.points, size: 4, fill: l.color },
        value: (u, v) => (v === null || v === undefined ? '–' : Number(v).toPrecision(5)),
      });
    }
    const plot = new uPlot(
      {
        width: plotWidth(target),
        height: options.height || 260,
        scales: { x: { time: false }, y: options.log ? { distr: 3 } : {} },
        axes: [{ label: xLabel }, {
          label: yLabel,
          size: 64,
          values: options.log ? (u, splits) => splits.map((v) => (v === null ? '' : v.toExponential(0))) : undefined,
        }],
        series,
        cursor: { drag: { x: true, y: false } },
      },
      joined,
      target.plot,
    );
    register(id, target, plot, countPoints(lines.map((l) => l.y)));
    return plot;
  }

  // A path in the plane (x-y or x-z): the samples joined in file order. uPlot's own line builder
  // assumes increasing x, which a trajectory does not have, so the path is drawn here.
  function polyline(u, seriesIndex) {
    const [xs, ys] = u.data[seriesIndex];
    const path = new Path2D();
    let started = false;
    for (let i = 0; i < xs.length; i++) {
      if (xs[i] === null || ys[i] === null) {
        started = false;
        continue;
      }
      const px = u.valToPos(xs[i], 'x', true);
      const py = u.valToPos(ys[i], 'y', true);
      if (started) path.lineTo(px, py);
      else path.moveTo(px, py);
      started = true;
    }
    return { stroke: path, fill: null, clip: null, band: null, gaps: null, flags: 0 };
  }

  // Equal metres per pixel on both axes, around all paths.
  function equalRanges(paths, width, height) {
    let [x0, x1, y0, y1] = [Infinity, -Infinity, Infinity, -Infinity];
    for (const p of paths) {
      for (let i = 0; i < p.x.length; i++) {
        if (p.x[i] === null || p.y[i] === null) continue;
        x0 = Math.min(x0, p.x[i]); x1 = Math.max(x1, p.x[i]);
        y0 = Math.min(y0, p.y[i]); y1 = Math.max(y1, p.y[i]);
      }
    }
    if (!Number.isFinite(x0)) return { x: [-1, 1], y: [-1, 1] };
    const plotW = width - 80, plotH = height - 70;  // less the axes
    const perPixel = Math.max((x1 - x0) / plotW, (y1 - y0) / plotH, 1e-6) * 1.08;
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    return {
      x: [cx - (perPixel * plotW) / 2, cx + (perPixel * plotW) / 2],
      y: [cy - (perPixel * plotH) / 2, cy + (perPixel * plotH) / 2],
    };
  }

  function pathChart(target, id, axes, paths) {
    const width = plotWidth(target), height = 420;
    const ranges = equalRanges(paths, width, height);
    const plot = new uPlot(
      {
        mode: 2,
        width,
        height,
        scales: {
          x: { time: false, auto: false, range: () => ranges.x },
          y: { auto: false, range: () => ranges.y },
        },
        axes: [{ label: axes[0] + ' (m)' }, { label: axes[1] + ' (m)', size: 64 }],
        series: [
          {},
          ...paths.map((p) => ({
            label: p.label,
            stroke: p.color,
            width: p.width || 1.25,
            dash: p.dash,
            paths: polyline,
            points: { show: false },
            facets: [{ scale: 'x', auto: false }, { scale: 'y', auto: false }],
          })),
        ],
        legend: { live: false },
        cursor: { drag: { x: true, y: true, uni: 20 } },
      },
      [null, ...paths.map((p) => [p.x, p.y])],
      target.plot,
    );
    register(id, target, plot, countPoints(paths.map((p) => p.x)));
  }

  // ---- sections -----------------------------------------------------------------------------
  function header() {
    const o = data.options;
    const inputs = [['reference', `${data.reference.path} (${data.reference.poses} poses${data.reference.has_velocity ? ', with velocity' : ''})`]];
    estimates.forEach((e, i) => inputs.push([`estimate ${i + 1}`, `${e.path} (${e.poses} poses${e.has_velocity ? ', with velocity' : ', no velocity'})`]));
    inputs.push(['options', `--align ${o.align}${o.n_align ? ' --n-align ' + o.n_align : ''} -r ${o.relation} --t-max-diff ${o.t_max_diff} --t-offset ${o.t_offset} --association ${o.association} --gt-velocity ${o.gt_velocity} --velocity-frame ${o.velocity_frame}`]);
    inputs.push(['plotted', `at most ${o.max_points} points per series (min/max per bucket over time; every k-th pose of a path)`]);
    definitions(document.getElementById('inputs'), inputs);
    document.getElementById('generator').textContent = data.generator;
    if (data.notes.length) {
      document.getElementById('notes-section').hidden = false;
      const list = document.getElementById('notes');
      for (const note of data.notes) list.append(el('li', { text: note }));
    }
  }

  function table() {
    const apeUnit = estimates[0].ape.metric.unit;
    const anyAse = estimates.some((e) => e.ase);
    const apeKeys = ['rmse', 'mean', 'median', 'std', 'min', 'max'];
    const aseKeys = ['rmse', 'std', 'median'];
    const partKeys = ['rotation', 'position', 'velocity'];
    const head1 = el('tr', { class: 'group' }, el('th', { text: '' }), el('th', { text: '' }),
      el('th', { colspan: apeKeys.length, text: `APE ${estimates[0].ape.metric.relation} (${apeUnit})` }));
    const head2 = el('tr', {}, el('th', { text: 'estimate' }), el('th', { text: 'pairs' }), ...apeKeys.map((k) => el('th', { text: k })));
    if (anyAse) {
      head1.append(el('th', { colspan: aseKeys.length + partKeys.length + 1, text: 'ASE on SE_2(3) (unit-less; parts: rad-like, m, m/s)' }));
      head2.append(...aseKeys.map((k) => el('th', { text: k })), ...partKeys.map((k) => el('th', { text: k + ' rmse' })), el('th', { text: 'ref. velocity' }));
    }
    head1.append(el('th', { text: '' }));
    head2.append(el('th', { text: 'alignment' }));
    const body = el('tbody');
    const bestApe = Math.min(...estimates.map((e) => e.ape.stats.rmse));
    const aseRmse = estimates.filter((e) => e.ase).map((e) => e.ase.stats.rmse);
    const bestAse = aseRmse.length ? Math.min(...aseRmse) : null;
    estimates.forEach((e, i) => {
      const row = el('tr', { 'data-estimate': String(i) });
      row.append(el('td', { title: e.path }, el('span', { class: 'swatch', style: `background:${colorOf(i)}` }), labels[i]));
      row.append(el('td', { text: String(e.ape.association.pairs) }));
      for (const k of apeKeys) {
        const cell = el('td', { text: fixed(e.ape.stats[k]), 'data-key': 'ape.' + k });
        if (k === 'rmse' && e.ape.stats.rmse === bestApe && estimates.length > 1) cell.classList.add('best');
        row.append(cell);
      }
      if (anyAse) {
        if (e.ase) {
          for (const k of aseKeys) {
            const cell = el('td', { text: fixed(e.ase.stats[k]), 'data-key': 'ase.' + k });
            if (k === 'rmse' && e.ase.stats.rmse === bestAse && aseRmse.length > 1) cell.classList.add('best');
            row.append(cell);
          }
          for (const k of partKeys) row.append(el('td', { text: e.ase.parts[k] ? fixed(e.ase.parts[k].rmse) : '–', 'data-key': 'ase.' + k }));
          row.append(el('td', { text: e.ase.velocity_source }));
        } else {
          row.append(el('td', { class: 'absent', colspan: aseKeys.length + partKeys.length + 1, text: e.ase_absent }));
        }
      }
      const a = e.ape.alignment;
      row.append(el('td', { text: a.method === 'none' ? 'none' : `${a.method}, scale ${a.scale.toPrecision(6)}` }));
      body.append(row);
    });
    document.getElementById('table').append(el('div', { class: 'table-wrap' }, el('table', {}, el('thead', {}, head1, head2), body)));
  }

  function trajectories() {
    const parent = document.getElementById('trajectories');
    for (const [id, a, b, title] of [['top', 'x', 'y', 'Top view (x-y)'], ['side', 'x', 'z', 'Side view (x-z)']]) {
      const paths = [{ label: 'reference', color: reference.color, width: 2, x: data.reference.path_xyz[a], y: data.reference.path_xyz[b] }];
      estimates.forEach((e, i) => paths.push({ label: labels[i], color: colorOf(i), x: e.path_xyz[a], y: e.path_xyz[b] }));
      pathChart(chartBox(parent, 'trajectory-' + id, title), 'trajectory-' + id, [a, b], paths);
    }
  }

  function errors() {
    const parent = document.getElementById('errors');
    const relation = estimates[0].ape.metric;
    lineChart(chartBox(parent, 'ape', `APE ${relation.relation} (${relation.unit})`), 'ape', timeLabel,
      `APE (${relation.unit})`,
      estimates.map((e, i) => ({ label: labels[i], color: colorOf(i), x: e.ape_series.t, y: e.ape_series.error })));
    const withAse = estimates.map((e, i) => ({ e, i })).filter(({ e }) => e.ase);
    const without = estimates.map((e, i) => ({ e, i })).filter(({ e }) => !e.ase).map(({ e, i }) => `${labels[i]} (${e.ase_absent})`);
    const missing = without.length ? `Not shown: ${without.join(', ')}; see the notes.` : '';
    if (!withAse.length) {
      parent.append(el('p', { class: 'chart-note', id: 'ase-absent', text: 'No estimate has an ASE: its charts are not shown. ' + missing }));
      return;
    }
    const parts = [['total', 'ASE on SE_2(3) (unit-less)', 'ASE'], ['rotation', 'ASE rotation part ‖R_qᵀR_p − I‖_F', 'rotation'],
      ['position', 'ASE position part (m)', 'position (m)'], ['velocity', 'ASE velocity part (m/s)', 'velocity (m/s)']];
    const row = el('div', { class: 'row' });
    for (const [key, title, axis] of parts) {
      const lines = withAse.filter(({ e }) => e.ase_series[key]).map(({ e, i }) => ({ label: labels[i], color: colorOf(i), x: e.ase_series.t, y: e.ase_series[key] }));
      if (!lines.length) continue;  // e.g. no rotation part for a position-only reference
      const id = key === 'total' ? 'ase' : 'ase-' + key;
      lineChart(chartBox(key === 'total' ? parent : row, id, title, key === 'total' ? missing : ''), id, timeLabel, axis, lines);
    }
    parent.append(row);
  }

  function velocity() {
    const parent = document.getElementById('velocity');
    const controls = document.getElementById('velocity-controls');
    const ref = data.reference_velocity;
    const sources = [['given', 'reference (own columns)', reference.given, 2, undefined],
      ['chebyshev', 'reference, Chebyshev', reference.chebyshev, 1.5, undefined],
      ['central', 'reference, central diff.', reference.central, 1, [4, 3]]];
    const withVelocity = estimates.map((e, i) => ({ e, i })).filter(({ e }) => e.velocity);
    const without = estimates.map((e, i) => ({ e, i })).filter(({ e }) => !e.velocity).map(({ i }) => labels[i]);
    const note = without.length ? `Not shown (no velocity): ${without.join(', ')}.` : '';
    if (!Object.keys(ref).length && !withVelocity.length) {
      parent.append(el('p', { class: 'chart-note', text: 'No velocity to show. ' + note }));
      return;
    }
    const target = chartBox(parent, 'velocity', 'Velocity', note);
    const draw = (component) => {
      const lines = [];
      for (const [key, label, color, width, dash] of sources) {
        if (ref[key]) lines.push({ label, color, width, dash, x: ref[key].t, y: ref[key][component] });
      }
      for (const { e, i } of withVelocity) lines.push({ label: labels[i], color: colorOf(i), x: e.velocity.t, y: e.velocity[component] });
      target.plot.replaceChildren();
      lineChart(target, 'velocity', timeLabel, component === 'speed' ? 'speed (m/s)' : component + ' (m/s)', lines, { height: 300 });
      for (const b of controls.querySelectorAll('button')) b.setAttribute('aria-pressed', String(b.dataset.component === component));
    };
    controls.append(el('span', { text: 'show' }));
    for (const component of ['speed', 'vx', 'vy', 'vz']) {
      const button = el('button', { type: 'button', 'data-component': component, text: component });
      button.addEventListener('click', () => draw(component));
      controls.append(button);
    }
    draw('speed');
  }

  function fit() {
    const parent = document.getElementById('fit');
    const f = data.fit;
    if (!f) {
      parent.append(el('p', { class: 'chart-note', text: 'No Chebyshev fit of the reference (see the notes).' }));
      return;
    }
    const axes = ['x', 'y', 'z'];
    const degrees = f.windows.flatMap((w) => w.degrees);
    definitions(document.getElementById('fit-summary'), [
      ['windows', `${f.windows.length} in ${f.segments} gap-free segment(s)`],
      ['degrees', `${Math.min(...degrees)} .. ${Math.max(...degrees)}`],
      ['noise σ (estimated)', f.noise_sigma.map((s) => s.toExponential(2) + ' m').join(', ')],
      ['fit residual RMS', f.residual_rms.map((s) => s.toExponential(2) + ' m').join(', ')],
    ]);
    const row = el('div', { class: 'row' });
    parent.append(row);
    const centre = f.windows.map((w) => (w.core_begin + w.core_end) / 2);
    lineChart(chartBox(row, 'fit-degrees', 'Chosen degree per window (at the window core’s centre)'), 'fit-degrees', timeLabel, 'degree',
      axes.map((a, c) => ({ label: a, color: palette[c], x: centre, y: f.windows.map((w) => w.degrees[c]), points: true })));

    const target = chartBox(row, 'fit-coefficients', 'Coefficient decay |c_k| in one window');
    const controls = el('div', { class: 'controls' });
    const slider = el('input', { type: 'range', min: '0', max: String(f.coefficients.length - 1), value: '0', step: '1', 'aria-label': 'window' });
    const label = el('span');
    controls.append(el('span', { text: 'window' }), slider, label);
    target.box.insertBefore(controls, target.plot);
    const draw = (index) => {
      const entry = f.coefficients[index];
      const w = f.windows[entry.window];
      label.textContent = `#${entry.window + 1} of ${f.windows.length}: ${w.begin.toFixed(2)} .. ${w.end.toFixed(2)} s, ${w.samples} samples, chosen degrees ${w.degrees.join(', ')}`;
      const k = entry.magnitudes[0].map((_, i) => i);
      const positive = (v) => (v > 0 ? v : null);  // a log scale has no zero
      const lines = axes.map((a, c) => ({ label: '|c_k| ' + a, color: palette[c], x: k, y: entry.magnitudes[c].map(positive), points: true, width: 1 }));
      axes.forEach((a, c) => lines.push({ label: 'noise level ' + a, color: palette[c], dash: [5, 4], width: 1, x: k, y: k.map(() => positive(entry.noise_level[c])) }));
      target.plot.replaceChildren();
      lineChart(target, 'fit-coefficients', 'k (Chebyshev index)', '|c_k| (m)', lines, { log: true });
    };
    slider.addEventListener('input', () => draw(Number(slider.value)));
    draw(0);
  }

  window.chevalReport = { charts, data };
  try {
    header();
    table();
    trajectories();
    errors();
    velocity();
    fit();
    window.addEventListener('resize', () => {
      for (const c of charts) c.plot.setSize({ width: plotWidth(c.target), height: c.plot.height });
    });
    document.body.dataset.ready = String(charts.length);
  } catch (error) {
    document.body.dataset.error = String(error && error.stack ? error.stack : error);
    throw error;
  }
})();
