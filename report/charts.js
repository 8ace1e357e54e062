// cheval report: the chart helpers of the page (report.js draws the sections with them). Charts over
// time and in the plane are uPlot instances; distributions are SVG drawn here. Every chart has an
// export bar (PNG, SVG, CSV): the SVG is written by svgDocument from what the chart shows (its
// current zoom), the PNG is that SVG rasterised at twice its size, the CSV is the plotted data.
'use strict';

const ChevalCharts = (function () {
  const charts = [];
  const palette = ['#0969da', '#cf222e', '#1a7f37', '#8250df', '#bc4c00', '#1b7c83', '#bf3989', '#6e7781'];

  function el(tag, attributes, ...children) {
    const node = document.createElement(tag);
    for (const [key, value] of Object.entries(attributes || {})) {
      if (key === 'text') node.textContent = value;
      else node.setAttribute(key, value);
    }
    for (const child of children) node.append(child);
    return node;
  }
  function countPoints(columns) {
    let n = 0;
    for (const column of columns) for (const v of column) if (v !== null && v !== undefined) n++;
    return n;
  }
  const finite = (v) => v !== null && v !== undefined && Number.isFinite(v);
  function extent(columns) {
    let lo = Infinity, hi = -Infinity;
    for (const c of columns) for (const v of c) if (finite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    return Number.isFinite(lo) ? [lo, hi] : [0, 1];
  }

  // A perceptually ordered colour map (viridis' end points and three stops between) for t in [0, 1].
  const stops = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  function colormap(t) {
    const x = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0)) * (stops.length - 1);
    const i = Math.min(stops.length - 2, Math.floor(x)), f = x - i;
    const c = stops[i].map((v, k) => Math.round(v + f * (stops[i + 1][k] - v)));
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  // ---- SVG ------------------------------------------------------------------------------------
  const escapeXml = (s) => String(s).replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);
  function niceTicks(lo, hi, count = 6) {
    if (!(hi > lo)) return [lo];
    const raw = (hi - lo) / count, magnitude = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 2.5, 5, 10].map((m) => m * magnitude).find((s) => s >= raw);
    const ticks = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) ticks.push(Math.abs(v) < step * 1e-9 ? 0 : v);
    return ticks;
  }
  const tickText = (v) => (Math.abs(v) >= 1e5 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(1) : String(Number(v.toPrecision(6))));

  // spec: {title, width, height, x: {label, min, max, log, categories}, y: {label, min, max, log},
  // items: [{type: 'line'|'segments'|'marker'|'rect'|'polygon', ...}], legend: [{label, color, dash}],
  // colorbar: {min, max, label}}. Coordinates of items are data values.
  function svgDocument(spec) {
    const W = spec.width || 720, H = spec.height || 360;
    const legend = spec.legend || [];
    // The legend on rows of swatch + label, as wide as the plot.
    const rows = [[]];
    let used = 0;
    for (const entry of legend) {
      const w = 30 + 6.6 * String(entry.label).length + 14;
      if (used + w > W - 90 && rows[rows.length - 1].length) { rows.push([]); used = 0; }
      rows[rows.length - 1].push({ entry, at: used });
      used += w;
    }
    const top = 30 + (legend.length ? 18 * rows.length + 4 : 0);
    const left = 70, right = spec.colorbar ? 86 : 16, bottom = 44;
    const pw = W - left - right, ph = H - top - bottom;
    const tx = (v) => (spec.x.log ? Math.log10(v) : v), ty = (v) => (spec.y.log ? Math.log10(v) : v);
    const [x0, x1] = [tx(spec.x.min), tx(spec.x.max)], [y0, y1] = [ty(spec.y.min), ty(spec.y.max)];
    const px = (v) => left + ((tx(v) - x0) / (x1 - x0 || 1)) * pw;
    const py = (v) => top + ph - ((ty(v) - y0) / (y1 - y0 || 1)) * ph;
    const ok = (x, y) => finite(x) && finite(y) && (!spec.x.log || x > 0) && (!spec.y.log || y > 0);
    const f = (v) => v.toFixed(1);
    const out = [`<svg xmlns="http://www.w3.org/2000/svg" width="${W}" height="${H}" viewBox="0 0 ${W} ${H}" font-family="Helvetica, Arial, sans-serif" font-size="11">`,
      `<rect width="${W}" height="${H}" fill="#fff"/>`,
      `<clipPath id="plot-area"><rect x="${left}" y="${top}" width="${pw}" height="${ph}"/></clipPath>`,
      `<text x="${left}" y="18" font-size="13" font-weight="bold">${escapeXml(spec.title || '')}</text>`];
    rows.forEach((row, r) => row.forEach(({ entry, at }) => {
      const y = 30 + 18 * r + 6, x = left + at;
      out.push(`<line x1="${x}" y1="${y}" x2="${x + 22}" y2="${y}" stroke="${entry.color}" stroke-width="${entry.width || 2.5}"${entry.dash ? ` stroke-dasharray="${entry.dash.join(' ')}"` : ''}/>`,
        `<text x="${x + 28}" y="${y + 4}">${escapeXml(entry.label)}</text>`);
    }));
    // Axes, ticks and grid.
    const yTicks = spec.y.log ? niceTicks(y0, y1).filter((v) => Number.isInteger(v)).map((v) => Math.pow(10, v)) : niceTicks(y0, y1);
    for (const v of yTicks) {
      out.push(`<line x1="${left}" x2="${left + pw}" y1="${f(py(v))}" y2="${f(py(v))}" stroke="#e5e8eb"/>`,
        `<text x="${left - 6}" y="${f(py(v) + 4)}" text-anchor="end">${escapeXml(spec.y.log ? v.toExponential(0) : tickText(v))}</text>`);
    }
    const xTicks = spec.x.categories ? spec.x.categories.map((c, i) => ({ v: i + 1, text: c })) : niceTicks(x0, x1).map((v) => ({ v, text: tickText(v) }));
    for (const { v, text } of xTicks) {
      out.push(`<line x1="${f(px(v))}" x2="${f(px(v))}" y1="${top}" y2="${top + ph}" stroke="#e5e8eb"/>`,
        `<text x="${f(px(v))}" y="${top + ph + 16}" text-anchor="middle">${escapeXml(text)}</text>`);
    }
    out.push(`<rect x="${left}" y="${top}" width="${pw}" height="${ph}" fill="none" stroke="#59636e"/>`,
      `<text x="${left + pw / 2}" y="${H - 8}" text-anchor="middle">${escapeXml(spec.x.label || '')}</text>`,
      `<text transform="translate(14 ${top + ph / 2}) rotate(-90)" text-anchor="middle">${escapeXml(spec.y.label || '')}</text>`,
      '<g clip-path="url(#plot-area)" fill="none">');
    for (const item of spec.items) {
      if (item.type === 'line') {
        let d = '', pen = 'M';
        for (let i = 0; i < item.x.length; i++) {
          if (!ok(item.x[i], item.y[i])) { pen = 'M'; continue; }
          d += `${pen}${f(px(item.x[i]))} ${f(py(item.y[i]))}`;
          pen = 'L';
        }
        if (d) out.push(`<path d="${d}" stroke="${item.color}" stroke-width="${item.width || 1.25}"${item.dash ? ` stroke-dasharray="${item.dash.join(' ')}"` : ''} stroke-linejoin="round"/>`);
      } else if (item.type === 'segments') {
        for (let i = 1; i < item.x.length; i++) {
          if (!ok(item.x[i - 1], item.y[i - 1]) || !ok(item.x[i], item.y[i]) || !finite(item.values[i])) continue;
          out.push(`<line x1="${f(px(item.x[i - 1]))}" y1="${f(py(item.y[i - 1]))}" x2="${f(px(item.x[i]))}" y2="${f(py(item.y[i]))}" stroke="${colormap((item.values[i] - item.vmin) / (item.vmax - item.vmin || 1))}" stroke-width="${item.width || 2}"/>`);
        }
      } else if (item.type === 'marker' && ok(item.x, item.y)) {
        const s = item.size || 5;
        out.push(item.shape === 'square'
          ? `<rect x="${f(px(item.x) - s)}" y="${f(py(item.y) - s)}" width="${2 * s}" height="${2 * s}" fill="${item.color}" stroke="#fff"/>`
          : `<circle cx="${f(px(item.x))}" cy="${f(py(item.y))}" r="${s}" fill="${item.color}" stroke="#fff"/>`);
      } else if (item.type === 'rect') {
        const [a, b] = [py(item.y0), py(item.y1)];
        out.push(`<rect x="${f(px(item.x0))}" y="${f(Math.min(a, b))}" width="${f(px(item.x1) - px(item.x0))}" height="${f(Math.abs(a - b))}" fill="${item.fill || 'none'}" fill-opacity="${item.opacity ?? 1}" stroke="${item.stroke || 'none'}"/>`);
      } else if (item.type === 'polygon') {
        const points = item.x.map((x, i) => `${f(px(x))},${f(py(item.y[i]))}`).join(' ');
        out.push(`<polygon points="${points}" fill="${item.fill}" fill-opacity="${item.opacity ?? 0.35}" stroke="${item.stroke || item.fill}"/>`);
      }
    }
    out.push('</g>');
    if (spec.colorbar) {
      const bx = left + pw + 14, steps = 32;
      for (let i = 0; i < steps; i++) {
        out.push(`<rect x="${bx}" y="${f(top + ph - ((i + 1) * ph) / steps)}" width="14" height="${f(ph / steps + 0.5)}" fill="${colormap(i / (steps - 1))}"/>`);
      }
      const { min, max, label } = spec.colorbar;
      for (const v of niceTicks(min, max, 4)) {
        out.push(`<text x="${bx + 18}" y="${f(top + ph - ((v - min) / (max - min || 1)) * ph + 4)}">${escapeXml(tickText(v))}</text>`);
      }
      out.push(`<text transform="translate(${W - 6} ${top + ph / 2}) rotate(-90)" text-anchor="middle">${escapeXml(label)}</text>`);
    }
    out.push('</svg>');
    return out.join('\n');
  }

  // ---- export ---------------------------------------------------------------------------------
  function download(name, blob) {
    const a = el('a', { href: URL.createObjectURL(blob), download: name });
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
  }
  function pngOf(svg) {
    return new Promise((resolve, reject) => {
      const image = new Image();
      image.onload = () => {
        const canvas = el('canvas', { width: String(image.width * 2), height: String(image.height * 2) });
        const context = canvas.getContext('2d');
        context.scale(2, 2);
        context.drawImage(image, 0, 0);
        canvas.toBlob((blob) => (blob ? resolve(blob) : reject(new Error('no PNG'))), 'image/png');
      };
      image.onerror = () => reject(new Error('the SVG could not be rasterised'));
      image.src = 'data:image/svg+xml;charset=utf-8,' + encodeURIComponent(svg);
    });
  }
  const csvCell = (v) => (v === null || v === undefined ? '' : /[",\n]/.test(String(v)) ? `"${String(v).replace(/"/g, '""')}"` : String(v));
  const csvOf = (header, rows) => [header, ...rows].map((r) => r.map(csvCell).join(',')).join('\n') + '\n';

  // ---- boxes ----------------------------------------------------------------------------------
  // A chart's box: a title, export buttons, the plot, an optional note. Returns the chart's entry.
  function chartBox(parent, id, title, note) {
    const plot = el('div', { class: 'plot' });
    const bar = el('span', { class: 'export' });
    const box = el('div', { class: 'chart', id: 'chart-' + id, 'data-chart': id }, el('div', { class: 'chart-head' }, el('h3', { text: title }), bar), plot);
    if (note) box.append(el('p', { class: 'chart-note', text: note }));
    parent.append(box);
    const entry = { id, title, box, plot, chart: null, svg: null, csv: null, points: 0 };
    for (const kind of ['PNG', 'SVG', 'CSV']) {
      const button = el('button', { type: 'button', 'data-export': kind.toLowerCase(), title: `Download this chart as ${kind}`, text: kind });
      button.addEventListener('click', async () => {
        if (kind === 'CSV') download(id + '.csv', new Blob([entry.csv()], { type: 'text/csv' }));
        else if (kind === 'SVG') download(id + '.svg', new Blob([entry.svg()], { type: 'image/svg+xml' }));
        else download(id + '.png', await pngOf(entry.svg()));
      });
      bar.append(button);
    }
    const known = charts.findIndex((c) => c.id === id);
    if (known >= 0) charts.splice(known, 1);
    charts.push(entry);
    return entry;
  }
  function width(entry) {
    return Math.max(320, Math.floor(entry.plot.getBoundingClientRect().width || 600));
  }
  function setPlot(entry, chart, points) {
    if (entry.chart && entry.chart.destroy) entry.chart.destroy();
    entry.plot.replaceChildren();
    entry.chart = chart;
    entry.points = points;
    entry.box.dataset.points = String(points);
  }
  const legendMarkers = (colors) => ({ markers: { width: 3, fill: (u, i) => colors[i], stroke: (u, i) => colors[i] } });

  // Lines over a sorted x: spec {xLabel, yLabel, lines: [{label, color, x, y, dash, width, points,
  // stepped, show}], log, height, range: [lo, hi] of y (else automatic), shade: [[x0, x1], ...] spans
  // drawn grey behind the lines}.
  function lineChart(entry, spec) {
    entry.redraw = () => lineChart(entry, spec);
    const lines = spec.lines;
    if (!lines.length) {
      setPlot(entry, null, 0);
      entry.plot.append(el('p', { class: 'chart-note', text: 'Nothing to show here.' }));
      entry.svg = () => svgDocument({ title: entry.title, x: { min: 0, max: 1 }, y: { min: 0, max: 1 }, items: [] });
      entry.csv = () => csvOf([spec.xLabel], []);
      return null;
    }
    const joined = uPlot.join(lines.map((l) => [l.x, l.y]));
    const series = [{ label: spec.xLabel, value: (u, v) => (v === null || v === undefined ? '–' : v.toFixed(3)) }];
    for (const l of lines) {
      series.push({
        label: l.label, stroke: l.color, width: l.width || 1.25, dash: l.dash, spanGaps: true, show: l.show !== false,
        paths: l.stepped ? uPlot.paths.stepped({ align: 1 }) : undefined,
        points: { show: !!l.points, size: 4, fill: l.color },
        value: (u, v) => (v === null || v === undefined ? '–' : Number(v).toPrecision(5)),
      });
    }
    const y = spec.log ? { distr: 3 } : spec.range ? { auto: false, range: () => entry.range || spec.range } : {};
    const target = entry.plot;
    setPlot(entry, null, 0);
    const chart = new uPlot({
      width: width(entry), height: spec.height || 240,
      scales: { x: { time: false }, y },
      axes: [{ label: spec.xLabel }, { label: spec.yLabel, size: 64, values: spec.log ? (u, s) => s.map((v) => (v === null ? '' : v.toExponential(0))) : undefined }],
      series, legend: legendMarkers([null, ...lines.map((l) => l.color)]),
      cursor: { drag: { x: true, y: false } },
      hooks: spec.shade ? { drawClear: [(u) => shadeSpans(u, spec.shade)] } : {},
    }, joined, target);
    setPlot(entry, chart, countPoints(lines.map((l) => l.y)));
    target.append(chart.root);
    entry.svg = () => svgDocument({
      title: entry.title, width: chart.width, height: chart.height + 40,
      x: { label: spec.xLabel, min: chart.scales.x.min, max: chart.scales.x.max },
      y: { label: spec.yLabel, min: chart.scales.y.min, max: chart.scales.y.max, log: !!spec.log },
      items: (spec.shade || []).map(([x0, x1]) => ({ type: 'rect', x0, x1, y0: chart.scales.y.min, y1: chart.scales.y.max, fill: shade, opacity: 0.15 }))
        .concat(lines.filter((l, i) => chart.series[i + 1].show).map((l) => ({ type: 'line', x: l.x, y: l.y, color: l.color, dash: l.dash, width: l.width }))),
      legend: lines.filter((l, i) => chart.series[i + 1].show).map((l) => ({ label: l.label, color: l.color, dash: l.dash })),
    });
    entry.csv = () => csvOf([spec.xLabel, ...lines.map((l) => l.label)], joined[0].map((x, r) => [x, ...joined.slice(1).map((c) => c[r])]));
    return chart;
  }

  // Spans [x0, x1] of the x axis shaded over the plot's height (behind the series).
  const shade = '#8c959f';
  function shadeSpans(u, spans) {
    const ctx = u.ctx;
    ctx.save();
    ctx.fillStyle = shade + '26';
    for (const [x0, x1] of spans) {
      const a = u.valToPos(x0, 'x', true), b = u.valToPos(x1, 'x', true);
      const left = Math.max(u.bbox.left, Math.min(a, b)), right = Math.min(u.bbox.left + u.bbox.width, Math.max(a, b));
      if (right > left) ctx.fillRect(left, u.bbox.top, right - left, u.bbox.height);
    }
    ctx.restore();
  }

  // A path in the plane joined in file order (uPlot's own line builder assumes increasing x).
  function polyline(u, seriesIndex) {
    const [xs, ys] = u.data[seriesIndex];
    const path = new Path2D();
    let started = false;
    for (let i = 0; i < xs.length; i++) {
      if (xs[i] === null || ys[i] === null) { started = false; continue; }
      const px = u.valToPos(xs[i], 'x', true), py = u.valToPos(ys[i], 'y', true);
      if (started) path.lineTo(px, py);
      else path.moveTo(px, py);
      started = true;
    }
    return { stroke: path, fill: null, clip: null, band: null, gaps: null, flags: 0 };
  }

  // Paths in the plane with equal metres per pixel, the height fitted to the paths' aspect, a start
  // (circle) and end (square) marker on each; spec.colorBy = {index, values, label} draws path
  // `index` coloured by its values instead of its colour. spec {axes, paths: [{label, color, x, y, width}]}.
  function pathChart(entry, spec) {
    entry.redraw = () => pathChart(entry, spec);
    const paths = spec.paths;
    const [x0, x1] = extent(paths.map((p) => p.x)), [y0, y1] = extent(paths.map((p) => p.y));
    const w = width(entry);
    const plotW = w - 80;
    const aspect = (y1 - y0 || 1e-6) / (x1 - x0 || 1e-6);
    const plotH = Math.min(620, Math.max(160, plotW * aspect));
    const h = plotH + 70;
    const perPixel = Math.max((x1 - x0) / plotW, (y1 - y0) / plotH, 1e-6) * 1.06;
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    const ranges = { x: [cx - (perPixel * plotW) / 2, cx + (perPixel * plotW) / 2], y: [cy - (perPixel * plotH) / 2, cy + (perPixel * plotH) / 2] };
    const colorBy = spec.colorBy;
    const [v0, v1] = colorBy ? extent([colorBy.values]) : [0, 1];
    const endsOf = (p) => {
      const at = [];
      for (let i = 0; i < p.x.length; i++) if (finite(p.x[i]) && finite(p.y[i])) at.push(i);
      return at.length ? [at[0], at[at.length - 1]] : null;
    };
    const drawExtras = (u) => {
      const ctx = u.ctx;
      ctx.save();
      if (colorBy) {
        const p = paths[colorBy.index];
        ctx.lineWidth = 2.5 * devicePixelRatio;
        for (let i = 1; i < p.x.length; i++) {
          if (!finite(p.x[i - 1]) || !finite(p.x[i]) || !finite(colorBy.values[i])) continue;
          ctx.strokeStyle = colormap((colorBy.values[i] - v0) / (v1 - v0 || 1));
          ctx.beginPath();
          ctx.moveTo(u.valToPos(p.x[i - 1], 'x', true), u.valToPos(p.y[i - 1], 'y', true));
          ctx.lineTo(u.valToPos(p.x[i], 'x', true), u.valToPos(p.y[i], 'y', true));
          ctx.stroke();
        }
      }
      paths.forEach((p, k) => {
        const ends = endsOf(p);
        if (!ends || !u.series[k + 1].show) return;
        ctx.fillStyle = p.color;
        ctx.strokeStyle = '#fff';
        const s = 4.5 * devicePixelRatio;
        const [sx, sy] = [u.valToPos(p.x[ends[0]], 'x', true), u.valToPos(p.y[ends[0]], 'y', true)];
        ctx.beginPath(); ctx.arc(sx, sy, s, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
        const [ex, ey] = [u.valToPos(p.x[ends[1]], 'x', true), u.valToPos(p.y[ends[1]], 'y', true)];
        ctx.fillRect(ex - s, ey - s, 2 * s, 2 * s); ctx.strokeRect(ex - s, ey - s, 2 * s, 2 * s);
      });
      ctx.restore();
    };
    setPlot(entry, null, 0);
    const chart = new uPlot({
      mode: 2, width: w, height: h,
      scales: { x: { time: false, auto: false, range: () => ranges.x }, y: { auto: false, range: () => ranges.y } },
      axes: [{ label: spec.axes[0] + ' (m)' }, { label: spec.axes[1] + ' (m)', size: 64 }],
      series: [{}, ...paths.map((p, k) => ({
        // Coloured by error: that path in the colour map over the others, faded.
        label: p.label, stroke: colorBy && k > 0 ? (colorBy.index === k ? 'rgba(0,0,0,0.08)' : p.color + '30') : p.color, width: p.width || 1.25,
        paths: polyline, points: { show: false }, facets: [{ scale: 'x', auto: false }, { scale: 'y', auto: false }],
      }))],
      legend: { live: false, ...legendMarkers([null, ...paths.map((p) => p.color)]) },
      cursor: { drag: { x: true, y: true, uni: 20 } },
      hooks: { draw: [drawExtras] },
    }, [null, ...paths.map((p) => [p.x, p.y])], entry.plot);
    setPlot(entry, chart, countPoints(paths.map((p) => p.x)));
    entry.plot.append(chart.root);
    if (colorBy) {
      const gradient = [0, 0.25, 0.5, 0.75, 1].map((t) => colormap(t)).join(', ');
      entry.plot.append(el('p', { class: 'colorbar' }, `${colorBy.label} of ${paths[colorBy.index].label}: ${v0.toPrecision(3)} `,
        el('span', { class: 'gradient', style: `background: linear-gradient(to right, ${gradient})` }), ` ${v1.toPrecision(3)}`));
    }
    entry.svg = () => {
      const shown = paths.map((p, k) => ({ p, k })).filter(({ k }) => chart.series[k + 1].show);
      const items = [];
      for (const { p, k } of shown) {
        if (colorBy && colorBy.index === k) items.push({ type: 'segments', x: p.x, y: p.y, values: colorBy.values, vmin: v0, vmax: v1, width: 2.5 });
        else items.push({ type: 'line', x: p.x, y: p.y, color: p.color, width: p.width });
      }
      for (const { p } of shown) {
        const ends = endsOf(p);
        if (ends) items.push({ type: 'marker', x: p.x[ends[0]], y: p.y[ends[0]], color: p.color }, { type: 'marker', shape: 'square', x: p.x[ends[1]], y: p.y[ends[1]], color: p.color });
      }
      return svgDocument({
        title: entry.title + ' (● start, ■ end)', width: chart.width, height: chart.height + 40,
        x: { label: spec.axes[0] + ' (m)', min: chart.scales.x.min, max: chart.scales.x.max },
        y: { label: spec.axes[1] + ' (m)', min: chart.scales.y.min, max: chart.scales.y.max },
        items, legend: shown.map(({ p }) => ({ label: p.label, color: p.color })),
        colorbar: colorBy ? { min: v0, max: v1, label: colorBy.label } : null,
      });
    };
    entry.csv = () => {
      const rows = [];
      paths.forEach((p, k) => p.x.forEach((x, i) => rows.push([p.label, x, p.y[i], colorBy && colorBy.index === k ? colorBy.values[i] : null])));
      return csvOf(['series', spec.axes[0], spec.axes[1], colorBy ? colorBy.label : 'value'], rows);
    };
    return chart;
  }

  // A chart drawn as SVG here (distributions): spec is svgDocument's; csv = {header, rows}.
  function svgChart(entry, spec, csv, points) {
    entry.redraw = () => svgChart(entry, spec, csv, points);
    const w = width(entry);
    const full = { ...spec, width: w, height: spec.height || 300 };
    setPlot(entry, { width: w, destroy() {} }, points);
    entry.plot.innerHTML = svgDocument(full);
    entry.svg = () => svgDocument(full);
    entry.csv = () => csvOf(csv.header, csv.rows);
  }

  // Every chart at the width of its box (a chart drawn before the other boxes of its row existed, or
  // before a resize, is drawn again).
  function relayout() {
    for (const c of charts) {
      if (c.chart && c.redraw && Math.abs(c.chart.width - width(c)) > 2) c.redraw();
    }
  }

  // Draws a page: window.chevalReport lists the charts and the data; `draw` makes the charts, which
  // are then fitted to their boxes (and again on a resize); the body gets data-ready (the number of
  // charts) or, if anything failed, data-error.
  function drawPage(data, draw) {
    window.chevalReport = { charts, data };
    try {
      draw();
      relayout();
      window.addEventListener('resize', relayout);
      document.body.dataset.ready = String(charts.length);
    } catch (error) {
      document.body.dataset.error = String(error && error.stack ? error.stack : error);
      throw error;
    }
  }

  return { drawPage, relayout, charts, palette, el, finite, extent, colormap, svgDocument, pngOf, csvOf, chartBox, lineChart, pathChart, svgChart };
})();
