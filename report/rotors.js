// cheval estimate rotors --report: draws the embedded data (the JSON of #cheval-data, written by
// cheval::report::RotorPageData) with the helpers of charts.js: the per-motor error table and, per
// motor, the estimated, measured and baseline rotor speeds over time. As on the report page, every
// chart's container gets data-chart and data-points, window.chevalReport lists the charts, and
// document.body gets data-ready when everything is drawn (data-error if something failed).
'use strict';

(function () {
  const { drawPage, el, chartBox, lineChart } = ChevalCharts;
  const data = JSON.parse(document.getElementById('cheval-data').textContent);
  const colors = { estimated: '#0969da', measured: '#1f2328', baseline: '#bc4c00' };
  const fixed = (v, digits) => (v === null || v === undefined || !Number.isFinite(v) ? '–' : v.toFixed(digits));

  function header() {
    const inputs = [['flight', data.flight], ['vehicle', data.vehicle],
      ['estimate', `${fixed(data.duration_s, 2)} s flying, ${data.scored_samples} of ${data.samples} samples scored; ${data.states} states in ${data.segments} segments, ${data.iterations} solver iterations${data.converged ? '' : ' (did not converge)'}, ${fixed(data.seconds, 3)} s`],
      ['plotted', `at most ${data.max_points} points per motor (min/max per bucket over time); the errors use every scored sample`]];
    const list = document.getElementById('inputs');
    for (const [term, value] of inputs) list.append(el('dt', { text: term }), el('dd', { text: value }));
    document.getElementById('generator').textContent = data.generator;
  }

  function table() {
    const head1 = el('tr', { class: 'group' }, el('th', { text: '' }), el('th', { colspan: '2', text: 'cheval' }), el('th', { colspan: '2', text: 'flatness baseline' }));
    const head2 = el('tr', {}, el('th', { text: 'motor' }), ...['rpm', '%', 'rpm', '%'].map((u) => el('th', { text: u })));
    const body = el('tbody');
    data.motors.forEach((motor, m) => {
      const row = el('tr', { 'data-motor': motor.name }, el('td', { text: motor.name }));
      const better = data.error.percent[m] <= data.baseline.percent[m] ? 'error' : 'baseline';
      for (const key of ['error', 'baseline']) {
        for (const [unit, digits] of [['rpm', 1], ['percent', 3]]) {
          const cell = el('td', { text: fixed(data[key][unit][m], digits), 'data-key': `${key}.${unit}` });
          if (key === better) cell.classList.add('best');
          row.append(cell);
        }
      }
      body.append(row);
    });
    document.getElementById('table').append(el('div', { class: 'table-wrap' }, el('table', {}, el('thead', {}, head1, head2), body)));
  }

  function motors() {
    const parent = document.getElementById('motors');
    data.motors.forEach((motor, m) => {
      const s = motor.series;
      const title = `${motor.name}: estimated ${fixed(data.error.percent[m], 2)} %, baseline ${fixed(data.baseline.percent[m], 2)} %`;
      lineChart(chartBox(parent, 'rotor-' + motor.name, title), {
        xLabel: 'time (s)', yLabel: `${motor.name} (${data.unit})`, height: 260, shade: data.unscored,
        lines: [
          { label: 'measured', color: colors.measured, width: 1.5, x: s.t, y: s.measured },
          { label: 'cheval', color: colors.estimated, width: 1.5, x: s.t, y: s.estimated },
          { label: 'flatness baseline', color: colors.baseline + '99', width: 1, x: s.t, y: s.baseline },
        ],
      });
    });
  }

  drawPage(data, () => {
    header();
    table();
    motors();
  });
})();
