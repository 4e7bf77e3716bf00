// The page's behaviour: the "Which method" ranking, sorting and filtering of the results table, and
// the address (`?rank=…&sort=…&desc=1&scenario=…&method=…&status=…&source=…`) that keeps them, so a
// view can be shared and the browser tests can open one. Plain DOM, no library: the page opens from
// disk with nothing fetched.
(function () {
  'use strict';
  var table = document.getElementById('results-table');
  if (!table) return;
  var headers = Array.prototype.slice.call(table.tHead.rows[0].cells);
  var body = table.tBodies[0];
  var rows = Array.prototype.slice.call(body.rows);
  var column = {};
  headers.forEach(function (th, i) { column[th.dataset.key] = i; });
  var params = new URLSearchParams(window.location.search);

  // A cell's value: its data-v number when it has one (NaN when empty), else its text.
  function value(row, key) {
    var cell = row.cells[column[key]];
    if (cell.dataset.v !== undefined) return cell.dataset.v === '' ? NaN : parseFloat(cell.dataset.v);
    return cell.textContent.trim();
  }

  // Keep the view in the address without reloading.
  function remember(key, v) {
    if (v === '' || v === null || v === undefined) params.delete(key); else params.set(key, v);
    var query = params.toString();
    history.replaceState(null, '', window.location.pathname + (query ? '?' + query : '') + window.location.hash);
  }

  // ---- Sorting: click a header; again to reverse. Missing values go last either way.
  var sortKey = null, descending = false;
  function sortBy(key, desc) {
    if (column[key] === undefined) return;
    sortKey = key; descending = desc;
    var sorted = rows.slice().sort(function (a, b) {
      var x = value(a, key), y = value(b, key);
      var xMissing = typeof x === 'number' && isNaN(x), yMissing = typeof y === 'number' && isNaN(y);
      if (xMissing || yMissing) return xMissing - yMissing;
      var order = typeof x === 'number' ? x - y : String(x).localeCompare(String(y));
      return desc ? -order : order;
    });
    sorted.forEach(function (r) { body.appendChild(r); });
    headers.forEach(function (th) {
      th.classList.toggle('sorted-up', th.dataset.key === key && !desc);
      th.classList.toggle('sorted-down', th.dataset.key === key && desc);
    });
    remember('sort', key); remember('desc', desc ? '1' : '');
  }
  headers.forEach(function (th) {
    th.classList.add('sortable');
    th.title = (th.title ? th.title + ' — ' : '') + 'click to sort';
    th.addEventListener('click', function () {
      sortBy(th.dataset.key, sortKey === th.dataset.key ? !descending : false);
    });
  });

  // ---- Filtering by test, method, status and data source (the rows' data attributes).
  // The dataset's (a collection's cases): edit family, mesh, open or closed, genus and size class;
  // a filter no row has a value for is left out.
  var filters = [['scenario', 'test'], ['method', 'method'], ['status', 'status'], ['source', 'data source'],
    ['family', 'edit family'], ['mesh', 'mesh'], ['surface', 'surface'], ['genus', 'genus'], ['size', 'size']]
    .filter(function (f) { return rows.some(function (r) { return r.dataset[f[0]] !== undefined; }); });
  var chosen = {};
  var filterBox = document.getElementById('filters');
  var counter = document.createElement('span');
  function applyFilters() {
    var shown = 0;
    rows.forEach(function (r) {
      var keep = filters.every(function (f) { return !chosen[f[0]] || r.dataset[f[0]] === chosen[f[0]]; });
      r.hidden = !keep;
      if (keep) shown += 1;
    });
    counter.textContent = shown + ' of ' + rows.length + ' rows';
    counter.dataset.shown = shown;
  }
  filters.forEach(function (f) {
    var key = f[0];
    var values = [];
    rows.forEach(function (r) {
      if (r.dataset[key] !== undefined && values.indexOf(r.dataset[key]) < 0) values.push(r.dataset[key]);
    });
    var label = document.createElement('label');
    label.textContent = f[1] + ' ';
    var select = document.createElement('select');
    select.id = 'filter-' + key;
    select.add(new Option('all', ''));
    values.forEach(function (v) { select.add(new Option(v, v)); });
    chosen[key] = values.indexOf(params.get(key)) >= 0 ? params.get(key) : '';
    select.value = chosen[key];
    select.addEventListener('change', function () {
      chosen[key] = select.value; remember(key, select.value); applyFilters();
    });
    label.appendChild(select);
    filterBox.appendChild(label);
  });
  counter.id = 'row-count';
  filterBox.appendChild(counter);
  applyFilters();
  if (params.get('sort')) sortBy(params.get('sort'), params.get('desc') === '1');

  // ---- "Which method": rank the `ok` cases of each test by the chosen measure (e_iso unless the
  // reader picks another); suspect, unfinished and failed cases are listed under each table with
  // their reasons, and ranked only when the reader asks for the suspect ones too.
  var rankBy = document.getElementById('rank-by');
  var rankSuspect = document.getElementById('rank-suspect');
  rankSuspect.checked = params.get('suspect') === '1';
  var ranking = document.getElementById('ranking');
  headers.filter(function (th) { return th.dataset.better; }).forEach(function (th) {
    rankBy.add(new Option(th.textContent, th.dataset.key));
  });
  rankBy.value = column[params.get('rank')] !== undefined && headers[column[params.get('rank')]].dataset.better
    ? params.get('rank') : 'e_iso';

  function cell(tag, text, cls) {
    var c = document.createElement(tag);
    c.textContent = text;
    if (cls) c.className = cls;
    return c;
  }
  function seconds(s) {
    if (isNaN(s)) return '–';
    return s < 1 ? (s * 1e3).toPrecision(3) + ' ms' : s.toPrecision(3) + ' s';
  }
  function rank() {
    var key = rankBy.value;
    var nearZero = headers[column[key]].dataset.better === 'near-zero';
    var badness = function (r) { var v = value(r, key); return nearZero ? Math.abs(v) : v; };
    var tests = [], ranks = {};
    rows.forEach(function (r) { if (tests.indexOf(r.dataset.scenario) < 0) tests.push(r.dataset.scenario); });
    ranking.textContent = '';
    var grid = document.createElement('div');
    grid.className = 'ranking-grid';
    tests.forEach(function (test) {
      var ranked = function (r) {
        return (r.dataset.status === 'ok' || (rankSuspect.checked && r.dataset.status === 'suspect')) &&
          !isNaN(badness(r));
      };
      var ofTest = rows.filter(function (r) { return r.dataset.scenario === test; });
      var finished = ofTest.filter(ranked).sort(function (a, b) { return badness(a) - badness(b); });
      var left = ofTest.filter(function (r) { return !ranked(r); });
      var t = document.createElement('table');
      t.className = 'ranking';
      t.dataset.scenario = test;
      var caption = document.createElement('caption');
      caption.textContent = test;
      t.appendChild(caption);
      var head = t.insertRow();
      ['#', 'method', headers[column[key]].textContent, 'per edit'].forEach(function (h) {
        head.appendChild(cell('th', h));
      });
      finished.forEach(function (r, i) {
        var tr = t.insertRow();
        tr.className = r.dataset.status;
        tr.dataset.method = r.dataset.method;
        tr.appendChild(cell('td', String(i + 1)));
        tr.appendChild(cell('td', r.dataset.method, 'text'));
        tr.appendChild(cell('td', r.cells[column[key]].textContent));
        tr.appendChild(cell('td', seconds(value(r, 'bind_s') + value(r, 'solve_s'))));
        (ranks[r.dataset.method] = ranks[r.dataset.method] || []).push(i + 1);
      });
      var box = document.createElement('div');
      box.appendChild(t);
      if (left.length) {
        var list = document.createElement('ul');
        list.className = 'unranked';
        list.appendChild(cell('li', 'not ranked:', 'unranked-head'));
        left.forEach(function (r) {
          var why = r.dataset.why ? ': ' + r.dataset.why : '';
          var li = cell('li', r.dataset.method + ' — ' + r.dataset.status + why);
          li.title = r.querySelector('td.status').textContent;
          li.className = r.dataset.status;
          li.dataset.method = r.dataset.method;
          list.appendChild(li);
        });
        box.appendChild(list);
      }
      grid.appendChild(box);
    });
    ranking.appendChild(grid);
    // Across tests: the median rank of each method over the tests it was ranked on.
    var medians = Object.keys(ranks).map(function (m) {
      var r = ranks[m].slice().sort(function (a, b) { return a - b; });
      var mid = Math.floor(r.length / 2);
      return [m, r.length % 2 ? r[mid] : (r[mid - 1] + r[mid]) / 2, r.length];
    }).sort(function (a, b) { return a[1] - b[1] || a[0].localeCompare(b[0]); });
    var across = document.createElement('table');
    across.id = 'median-ranks';
    across.appendChild(cell('caption', 'median rank over the tests where it was ranked'));
    var head = across.insertRow();
    ['method', 'median rank', 'tests ranked'].forEach(function (h) { head.appendChild(cell('th', h)); });
    medians.forEach(function (m) {
      var tr = across.insertRow();
      tr.dataset.method = m[0];
      tr.appendChild(cell('td', m[0], 'text'));
      tr.appendChild(cell('td', String(m[1])));
      tr.appendChild(cell('td', String(m[2])));
    });
    ranking.appendChild(across);
    remember('rank', key === 'e_iso' ? '' : key);
    remember('suspect', rankSuspect.checked ? '1' : '');
  }
  rankBy.addEventListener('change', rank);
  rankSuspect.addEventListener('change', rank);
  rank();

  // The first two columns stay in view while the table scrolls sideways.
  var first = headers[0].offsetWidth;
  [headers[1]].concat(rows.map(function (r) { return r.cells[1]; })).forEach(function (c) {
    c.style.left = first + 'px';
  });
})();
