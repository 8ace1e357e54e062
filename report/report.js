// cheval report: draws the embedded data (the JSON of the script element #cheval-data, written by
// cheval::report::BuildReport) with the helpers of charts.js. Every chart's container gets
// data-chart (its name) and data-points (the points it plots), window.chevalReport lists the charts,
// and document.body gets data-ready when everything is drawn (data-error if something failed).
'use strict';

(function () {
  const { drawPage, relayout, palette, el, finite, extent, chartBox, lineChart, pathChart, svgChart } = ChevalCharts;
  const data = JSON.parse(document.getElementById('cheval-data').textContent);
  const reference = { color: '#1f2328', chebyshev: '#1f2328', central: '#8c959f', given: '#bf8700' };
  const timeLabel = data.time_axis === 's' ? 'time (s)' : 'pose index';
  const estimates = data.estimates;
  const colorOf = (i) => palette[i % palette.length];
  const labels = estimates.map((e) => e.label);
  const indexed = (predicate) => estimates.map((e, i) => ({ e, i })).filter(({ e }) => predicate(e));

  function definitions(list, pairs) {
    for (const [term, value] of pairs) list.append(el('dt', { text: term }), el('dd', { text: value }));
  }
  function fixed(value, digits = 6) {
    return value === null || value === undefined || !Number.isFinite(value) ? '–' : value.toFixed(digits);
  }
  function buttons(parent, title, choices, onChoose, initial) {
    const bar = el('div', { class: 'controls' }, el('span', { text: title }));
    const set = (key) => {
      for (const b of bar.querySelectorAll('button')) b.setAttribute('aria-pressed', String(b.dataset.choice === String(key)));
      onChoose(key);
    };
    for (const [key, text] of choices) {
      const b = el('button', { type: 'button', 'data-choice': String(key), text });
      b.addEventListener('click', () => set(key));
      bar.append(b);
    }
    parent.append(bar);
    return { bar, set, initial: () => set(initial) };
  }

  // ---- header and table -----------------------------------------------------------------------
  function header() {
    const o = data.options;
    const named = (x) => (o.show_paths && x.path !== x.label ? `${x.label} — ${x.path}` : x.label);
    const inputs = [['reference', `${named(data.reference)} (${data.reference.poses} poses${data.reference.has_velocity ? ', with velocity' : ''})`]];
    estimates.forEach((e, i) => inputs.push([`estimate ${i + 1}`, `${named(e)} (${e.poses} poses${e.has_velocity ? ', with velocity' : ', no velocity'})`]));
    inputs.push(['options', `--align ${o.align}${o.n_align ? ' --n-align ' + o.n_align : ''} -r ${o.relation} --t-max-diff ${o.t_max_diff} --t-offset ${o.t_offset} --association ${o.association} --gt-velocity ${o.gt_velocity} --velocity-frame ${o.velocity_frame}`]);
    inputs.push(['plotted', `at most ${o.max_points} points per series (min/max per bucket over time; every k-th pose of a path); the statistics and distributions use every pair`]);
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
    const head1 = el('tr', { class: 'group' }, el('th', { text: '' }), el('th', { text: '' }),
      el('th', { colspan: apeKeys.length, text: `APE ${estimates[0].ape.metric.relation} (${apeUnit})` }));
    const head2 = el('tr', {}, el('th', { text: 'estimate' }), el('th', { text: 'pairs' }), ...apeKeys.map((k) => el('th', { text: k })));
    if (anyAse) {
      head1.append(el('th', { colspan: aseKeys.length + 4, text: 'ASE on SE_2(3) (unit-less; parts: rotation in degrees, m, m/s)' }));
      head2.append(...aseKeys.map((k) => el('th', { text: k })), el('th', { text: 'rotation rmse (°)' }), el('th', { text: 'position rmse' }),
        el('th', { text: 'velocity rmse' }), el('th', { text: 'ref. velocity' }));
    }
    head1.append(el('th', { text: '' }));
    head2.append(el('th', { text: 'alignment' }));
    const body = el('tbody');
    const bestApe = Math.min(...estimates.map((e) => e.ape.stats.rmse));
    const aseRmse = estimates.filter((e) => e.ase).map((e) => e.ase.stats.rmse);
    const bestAse = aseRmse.length ? Math.min(...aseRmse) : null;
    estimates.forEach((e, i) => {
      const row = el('tr', { 'data-estimate': String(i) });
      row.append(el('td', {}, el('span', { class: 'swatch', style: `background:${colorOf(i)}` }), labels[i]));
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
          row.append(el('td', { text: e.ase_rotation_deg ? fixed(e.ase_rotation_deg.rmse, 4) : '–', 'data-key': 'ase.rotation_deg' }));
          for (const k of ['position', 'velocity']) row.append(el('td', { text: e.ase.parts[k] ? fixed(e.ase.parts[k].rmse) : '–', 'data-key': 'ase.' + k }));
          row.append(el('td', { text: e.ase.velocity_source }));
        } else {
          row.append(el('td', { class: 'absent', colspan: aseKeys.length + 4, text: e.ase_absent }));
        }
      }
      const a = e.ape.alignment;
      row.append(el('td', { text: a.method === 'none' ? 'none' : `${a.method}, scale ${a.scale.toPrecision(6)}` }));
      body.append(row);
    });
    document.getElementById('table').append(el('div', { class: 'table-wrap' }, el('table', {}, el('thead', {}, head1, head2), body)));
  }

  // ---- trajectories, position and orientation ---------------------------------------------------
  function trajectories() {
    const parent = document.getElementById('trajectories');
    const views = [['top', 'x', 'y', 'Top view (x-y)'], ['side', 'x', 'z', 'Side view (x-z)']];
    const entries = views.map(([id, , , title]) => chartBox(parent, 'trajectory-' + id, title));
    const draw = (colored) => views.forEach(([, a, b], v) => {
      const paths = [{ label: data.reference.label + ' (reference)', color: reference.color, width: 2, x: data.reference.path_xyz[a], y: data.reference.path_xyz[b] }];
      estimates.forEach((e, i) => paths.push({ label: labels[i], color: colorOf(i), x: e.path_xyz[a], y: e.path_xyz[b] }));
      const colorBy = colored === 'none' ? null : { index: Number(colored) + 1, values: estimates[colored].path_xyz.error, label: `APE (${estimates[colored].ape.metric.unit})` };
      pathChart(entries[v], { axes: [a, b], paths, colorBy });
    });
    const choice = buttons(document.getElementById('trajectory-controls'), 'colour by APE:', [['none', 'none'], ...labels.map((l, i) => [i, l])], draw, 'none');
    choice.initial();
  }

  function overTime() {
    const parent = document.getElementById('pose-charts');
    const groups = [['position', [['x', 'x (m)'], ['y', 'y (m)'], ['z', 'z (m)']]], ['orientation', [['roll', 'roll (°)'], ['pitch', 'pitch (°)'], ['yaw', 'yaw (°)']]]];
    for (const [group, axes] of groups) {
      const row = el('div', { class: 'row three' });
      parent.append(row);
      for (const [key, axis] of axes) {
        const lines = [];
        const ref = data.reference.path_xyz;
        if (ref[key]) lines.push({ label: 'reference', color: reference.color, width: 1.5, x: ref.t, y: ref[key] });
        estimates.forEach((e, i) => { if (e.path_xyz[key]) lines.push({ label: labels[i], color: colorOf(i), x: e.path_xyz.t, y: e.path_xyz[key] }); });
        if (!lines.length) {
          if (key === 'roll') row.append(el('p', { class: 'chart-note', id: 'orientation-absent', text: 'No orientation to show (position-only files).' }));
          continue;
        }
        lineChart(chartBox(row, key, `${group === 'position' ? 'Position' : 'Orientation'}: ${axis}`), { xLabel: timeLabel, yLabel: axis, lines, height: 200 });
      }
    }
  }

  // ---- errors over time and their distributions ---------------------------------------------------
  function errors() {
    const parent = document.getElementById('errors');
    const relation = estimates[0].ape.metric;
    lineChart(chartBox(parent, 'ape', `APE ${relation.relation} (${relation.unit})`), {
      xLabel: timeLabel, yLabel: `APE (${relation.unit})`,
      lines: estimates.map((e, i) => ({ label: labels[i], color: colorOf(i), x: e.ape_series.t, y: e.ape_series.error })),
    });
    const withAse = indexed((e) => e.ase);
    const without = indexed((e) => !e.ase).map(({ e, i }) => `${labels[i]} (${e.ase_absent})`);
    const missing = without.length ? `Not shown: ${without.join(', ')}; see the notes.` : '';
    if (!withAse.length) {
      parent.append(el('p', { class: 'chart-note', id: 'ase-absent', text: 'No estimate has an ASE: its charts are not shown. ' + missing }));
      return;
    }
    const parts = [['total', 'ASE on SE_2(3) (unit-less)', 'ASE'], ['rotation_deg', 'ASE rotation part (°)', 'rotation (°)'],
      ['position', 'ASE position part (m)', 'position (m)'], ['velocity', 'ASE velocity part (m/s)', 'velocity (m/s)']];
    const row = el('div', { class: 'row three' });
    for (const [key, title, axis] of parts) {
      const lines = withAse.filter(({ e }) => e.ase_series[key]).map(({ e, i }) => ({ label: labels[i], color: colorOf(i), x: e.ase_series.t, y: e.ase_series[key] }));
      if (!lines.length) continue;  // e.g. no rotation part for a position-only reference
      const id = key === 'total' ? 'ase' : 'ase-' + key.replace('_deg', '');
      lineChart(chartBox(key === 'total' ? parent : row, id, title, key === 'total' ? missing : ''), { xLabel: timeLabel, yLabel: axis, lines, height: key === 'total' ? 240 : 200 });
    }
    parent.append(row);
  }

  // Box plots (matplotlib's: quartiles, whiskers at 1.5 IQR, no outliers) of groups of boxes.
  function boxItems(box, center, halfWidth, color) {
    return [
      { type: 'line', x: [center, center], y: [box.whisker_low, box.q1], color },
      { type: 'line', x: [center, center], y: [box.q3, box.whisker_high], color },
      { type: 'line', x: [center - halfWidth / 2, center + halfWidth / 2], y: [box.whisker_low, box.whisker_low], color },
      { type: 'line', x: [center - halfWidth / 2, center + halfWidth / 2], y: [box.whisker_high, box.whisker_high], color },
      { type: 'rect', x0: center - halfWidth, x1: center + halfWidth, y0: box.q1, y1: box.q3, fill: color, opacity: 0.25, stroke: color },
      { type: 'line', x: [center - halfWidth, center + halfWidth], y: [box.median, box.median], color, width: 2 },
    ];
  }
  const boxHeader = ['estimate', 'n', 'min', 'whisker_low', 'q1', 'median', 'q3', 'whisker_high', 'max', 'mean', 'rmse'];
  const boxRow = (name, b) => [name, b.n, b.min, b.whisker_low, b.q1, b.median, b.q3, b.whisker_high, b.max, b.mean, b.rmse];

  function distributionCharts(row, key, what, unit) {
    const items = indexed((e) => e[key]);
    if (!items.length) return;
    // Histogram: each estimate's density (count / (n · bin width)) as a step line.
    const lines = [];
    let top = 0;
    for (const { e, i } of items) {
      const d = e[key];
      const x = [], y = [];
      d.counts.forEach((c, b) => {
        const density = c / (d.box.n * d.bin_width);
        top = Math.max(top, density);
        x.push(d.bin_start + b * d.bin_width, d.bin_start + (b + 1) * d.bin_width);
        y.push(density, density);
      });
      lines.push({ label: labels[i], color: colorOf(i), x: [x[0], ...x, x[x.length - 1]], y: [0, ...y, 0], width: 1.5 });
    }
    const [lo, hi] = extent(lines.map((l) => l.x));
    svgChart(chartBox(row, key.replace('_distribution', '') + '-histogram', `${what} histogram`), {
      title: `${what} histogram`, x: { label: `${what} (${unit})`, min: lo, max: hi }, y: { label: 'density', min: 0, max: top * 1.05 },
      items: lines.map((l) => ({ type: 'line', ...l })), legend: lines.map((l) => ({ label: l.label, color: l.color })),
    }, { header: ['estimate', 'bin_start', 'bin_end', 'count'], rows: items.flatMap(({ e, i }) => e[key].counts.map((c, b) => [labels[i], e[key].bin_start + b * e[key].bin_width, e[key].bin_start + (b + 1) * e[key].bin_width, c])) },
    lines.reduce((n, l) => n + l.x.length, 0));
    // Violins (the density, mirrored) with the box inside.
    const shapes = [];
    let ymax = 0;
    items.forEach(({ e, i }, k) => {
      const d = e[key];
      const peak = Math.max(...d.density) || 1;
      const left = d.density.map((v) => k + 1 - (0.4 * v) / peak), right = d.density.map((v) => k + 1 + (0.4 * v) / peak);
      shapes.push({ type: 'polygon', x: [...left, ...right.reverse()], y: [...d.density_at, ...d.density_at.slice().reverse()], fill: colorOf(i), opacity: 0.2 });
      shapes.push(...boxItems(d.box, k + 1, 0.08, colorOf(i)));
      ymax = Math.max(ymax, d.box.max, d.density_at[d.density_at.length - 1]);
    });
    svgChart(chartBox(row, key.replace('_distribution', '') + '-violin', `${what} per estimate: violin and box`), {
      title: `${what} per estimate`, x: { label: 'estimate', min: 0.5, max: items.length + 0.5, categories: items.map(({ i }) => labels[i]) },
      y: { label: `${what} (${unit})`, min: 0, max: ymax * 1.03 }, items: shapes,
    }, { header: boxHeader, rows: items.map(({ e, i }) => boxRow(labels[i], e[key].box)) }, shapes.length);
  }

  function distributions() {
    const row = el('div', { class: 'row four' });
    document.getElementById('distributions').append(row);
    distributionCharts(row, 'ape_distribution', 'APE', estimates[0].ape.metric.unit || 'unit-less');
    distributionCharts(row, 'ase_distribution', 'ASE', 'unit-less');
  }

  // ---- RPE --------------------------------------------------------------------------------------
  function rpe() {
    const parent = document.getElementById('rpe');
    const distances = data.rpe_distances;
    const rows = estimates.map((e) => new Map(e.rpe.distances.map((d) => [d.delta, d])));
    if (!distances.length || rows.every((r) => !r.size)) {
      parent.append(el('p', { class: 'chart-note', id: 'rpe-absent', text: 'No RPE: the reference path is too short for its distances (see the notes).' }));
      return;
    }
    const rotation = estimates.some((e) => e.rpe.rotation);
    const parts = [['trans', 'translation (m)']].concat(rotation ? [['rot', 'rotation (°)']] : []);
    // Box plots per distance, one box per estimate in its colour, as rpg_trajectory_evaluation draws them.
    const boxes = el('div', { class: 'row' });
    parent.append(boxes);
    for (const [key, axis] of parts) {
      const items = [];
      const csv = [];
      let ymax = 0;
      const n = estimates.length, slot = 0.8 / n;
      distances.forEach((delta, g) => estimates.forEach((e, i) => {
        const d = rows[i].get(delta);
        if (!d || !d[key]) return;
        items.push(...boxItems(d[key], g + 1 - 0.4 + slot * (i + 0.5), slot * 0.35, colorOf(i)));
        ymax = Math.max(ymax, d[key].whisker_high);
        csv.push(boxRow(labels[i], d[key]).concat([delta]));
      }));
      svgChart(chartBox(boxes, 'rpe-box-' + key, `RPE ${axis} per distance`), {
        title: `RPE ${axis} per distance`, x: { label: 'distance travelled (m)', min: 0.5, max: distances.length + 0.5, categories: distances.map(String) },
        y: { label: `RPE ${axis}`, min: 0, max: ymax * 1.05 || 1 }, items, legend: estimates.map((e, i) => ({ label: labels[i], color: colorOf(i) })),
      }, { header: boxHeader.concat(['distance_m']), rows: csv }, items.length);
    }
    // Over time at one distance (buttons).
    const timeRow = el('div', { class: 'row' });
    const targets = parts.map(([key, axis]) => [key, axis, chartBox(timeRow, 'rpe-' + key, `RPE ${axis} over time`)]);
    const draw = (delta) => {
      for (const [key, axis, target] of targets) {
        const lines = [];
        estimates.forEach((e, i) => {
          const d = rows[i].get(delta);
          if (d && d.series[key]) lines.push({ label: labels[i], color: colorOf(i), x: d.series.t, y: d.series[key] });
        });
        target.title = `RPE ${axis} over ${delta} m`;
        target.box.querySelector('h3').textContent = target.title;
        lineChart(target, { xLabel: timeLabel, yLabel: `RPE ${axis}`, lines });
      }
    };
    const choice = buttons(parent, 'RPE over time at distance:', distances.map((d) => [d, d + ' m']), draw, distances[0]);
    parent.append(timeRow);
    choice.initial();
  }

  // ---- velocity ---------------------------------------------------------------------------------
  function velocity() {
    const parent = document.getElementById('velocity');
    const controls = document.getElementById('velocity-controls');
    const ref = data.reference_velocity;
    const sources = [['given', 'reference (own columns)', reference.given, 2, undefined],
      ['chebyshev', 'reference, Chebyshev', reference.chebyshev, 1.5, undefined],
      ['central', 'reference, central diff.', reference.central, 1, [4, 3]]];
    const withVelocity = indexed((e) => e.velocity);
    const without = indexed((e) => !e.velocity).map(({ i }) => labels[i]);
    const note = without.length ? `Not shown (no velocity): ${without.join(', ')}.` : '';
    if (!Object.keys(ref).length && !withVelocity.length) {
      parent.append(el('p', { class: 'chart-note', text: 'No velocity to show. ' + note }));
      return;
    }
    const target = chartBox(parent, 'velocity', 'Velocity', note);
    let component = 'speed', central = false;
    const draw = () => {
      const lines = [];
      for (const [key, label, color, width, dash] of sources) {
        if (ref[key]) lines.push({ label, color, width, dash, x: ref[key].t, y: ref[key][component], show: key !== 'central' || central, key });
      }
      for (const { e, i } of withVelocity) lines.push({ label: labels[i], color: colorOf(i), x: e.velocity.t, y: e.velocity[component] });
      // The y-range of the motion: the reference's smooth velocity (its own, else Chebyshev), not the
      // spikes of central differences or of a noisy estimate; all shown lines when neither exists.
      const motion = lines.filter((l) => l.key === 'given' || l.key === 'chebyshev');
      const [lo, hi] = extent((motion.length ? motion : lines.filter((l) => l.show !== false)).map((l) => l.y));
      const pad = 0.15 * (hi - lo || 1);
      target.range = [component === 'speed' ? Math.max(0, lo - pad) : lo - pad, hi + pad];
      const chart = lineChart(target, { xLabel: timeLabel, yLabel: component === 'speed' ? 'speed (m/s)' : component + ' (m/s)', lines, height: 300, range: target.range });
      target.box.dataset.central = String(central);
      return chart;
    };
    const choice = buttons(controls, 'show', ['speed', 'vx', 'vy', 'vz'].map((c) => [c, c]), (c) => { component = c; draw(); }, 'speed');
    if (ref.central) {
      const toggle = el('button', { type: 'button', id: 'toggle-central', 'aria-pressed': 'false', text: 'central differences' });
      toggle.addEventListener('click', () => { central = !central; toggle.setAttribute('aria-pressed', String(central)); draw(); });
      choice.bar.append(el('span', { text: '·' }), toggle);
    }
    choice.initial();
  }

  // ---- fit diagnostics (collapsed; drawn when opened) ----------------------------------------------
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
      ['noise σ (estimated)', f.noise_sigma.map((s) => s.toExponential(2) + ' m').join(', ')
        + (f.noisier_samples > 0 ? ` (up to ${f.noise_sigma_max.map((s) => s.toExponential(2)).join(', ')} m over ${f.noisier_samples} noisier samples)` : '')],
      ...((f.at_rounding || []).some((a) => a) ? [['rounded positions', `${f.resolution.map((q, c) => (f.at_rounding[c] ? `${'xyz'[c]} to ${(1e3 * q).toPrecision(3)} mm` : null)).filter((x) => x).join(', ')}: their differences read no more noise than the rounding makes, step/√12 with any noise before it, which the fit takes as their noise`]] : []),
      ...((f.staircase || []).some((a) => a) ? [['rounded positions, placed', `${f.resolution.map((q, c) => (f.staircase[c] ? `${'xyz'[c]} to ${(1e3 * q).toPrecision(3)} mm` : null)).filter((x) => x).join(', ')}: they move less than a step a sample, and were placed between their steps, on a curve through the instants they pass from one step to the next`]] : []),
      ...(f.stamp_noise_s > 0 ? [['stamp noise', `the samples scatter in proportion to their rate, as stamps off by ${(1e3 * f.stamp_noise_s).toPrecision(3)} ms (RMS) make them; the fit takes that noise into account`]] : []),
      ['fit residual RMS', f.residual_rms.map((s) => s.toExponential(2) + ' m').join(', ')],
      ['residual test', f.unresolved_windows === 0 ? 'every window passed'
        : `${f.unresolved_windows} window(s) failed at the smallest size; ${f.local_samples} samples followed by the local interpolant`],
    ]);
    const details = document.getElementById('fit-section');
    let drawn = false;
    const draw = () => {
      if (drawn || !details.open) return;
      drawn = true;
      const row = el('div', { class: 'row' });
      parent.append(row);
      const centre = f.windows.map((w) => (w.core_begin + w.core_end) / 2);
      lineChart(chartBox(row, 'fit-degrees', 'Chosen degree per window (at the window core’s centre)'), {
        xLabel: timeLabel, yLabel: 'degree', lines: axes.map((a, c) => ({ label: a, color: palette[c], x: centre, y: f.windows.map((w) => w.degrees[c]), points: true })),
      });
      // Residual against the noise per window: a fit that resolved the motion leaves about σ.
      const tested = f.windows.filter((w) => w.residual_rms);
      if (tested.length > 0) {
        const at = tested.map((w) => (w.core_begin + w.core_end) / 2);
        const positive = (v) => (v > 0 ? v : null);
        const lines = axes.map((a, c) => ({ label: 'residual RMS ' + a, color: palette[c], x: at, y: tested.map((w) => positive(w.residual_rms[c])), points: true, width: 1 }));
        // Each window's σ is the noise profile's over its samples (the recording's where it has none).
        axes.forEach((a, c) => lines.push({ label: 'noise σ ' + a, color: palette[c], dash: [5, 4], width: 1, x: at, y: tested.map((w) => positive((w.noise_sigma || f.noise_sigma)[c])) }));
        lineChart(chartBox(row, 'fit-residual', 'Residual RMS per window against the noise σ it was tested against'), { xLabel: timeLabel, yLabel: 'm', lines, log: true });
      }
      const target = chartBox(row, 'fit-coefficients', 'Coefficient decay |c_k| in one window');
      const controls = el('div', { class: 'controls' });
      const slider = el('input', { type: 'range', min: '0', max: String(f.coefficients.length - 1), value: '0', step: '1', 'aria-label': 'window' });
      const label = el('span');
      controls.append(el('span', { text: 'window' }), slider, label);
      target.box.insertBefore(controls, target.plot);
      const drawWindow = (index) => {
        const entry = f.coefficients[index];
        const w = f.windows[entry.window];
        label.textContent = `#${entry.window + 1} of ${f.windows.length}: ${w.begin.toFixed(2)} .. ${w.end.toFixed(2)} s, ${w.samples} samples, chosen degrees ${w.degrees.join(', ')}`;
        const k = entry.magnitudes[0].map((_, i) => i);
        const positive = (v) => (v > 0 ? v : null);  // a log scale has no zero
        const lines = axes.map((a, c) => ({ label: '|c_k| ' + a, color: palette[c], x: k, y: entry.magnitudes[c].map(positive), points: true, width: 1 }));
        axes.forEach((a, c) => lines.push({ label: 'noise level ' + a, color: palette[c], dash: [5, 4], width: 1, x: k, y: k.map(() => positive(entry.noise_level[c])) }));
        lineChart(target, { xLabel: 'k (Chebyshev index)', yLabel: '|c_k| (m)', lines, log: true });
      };
      slider.addEventListener('input', () => drawWindow(Number(slider.value)));
      drawWindow(0);
      relayout();
    };
    details.addEventListener('toggle', draw);
    draw();
  }

  drawPage(data, () => {
    header();
    table();
    trajectories();
    overTime();
    errors();
    distributions();
    rpe();
    velocity();
    fit();
  });
})();
