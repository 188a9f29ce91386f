// SPDX-License-Identifier: MIT
// The report's sortable tables (inlined into report.html): click a heading to sort by
// it, again to reverse. Numbers sort by value (data-sort), the rest as text.
'use strict';
for (const table of document.querySelectorAll('table.sortable')) {
  const heads = table.tHead.rows[0].cells;
  for (let i = 0; i < heads.length; i++) {
    heads[i].addEventListener('click', () => {
      const th = heads[i];
      const ascending = !th.classList.contains('sorted-asc');
      for (const h of heads) h.classList.remove('sorted-asc', 'sorted-desc');
      th.classList.add(ascending ? 'sorted-asc' : 'sorted-desc');
      const numeric = th.dataset.type === 'num';
      const body = table.tBodies[0];
      const rows = Array.from(body.rows);
      const key = (row) => {
        const c = row.cells[i];
        const v = c.dataset.sort !== undefined ? c.dataset.sort : c.textContent;
        return numeric ? parseFloat(v) : v;
      };
      rows.sort((a, b) => {
        const x = key(a), y = key(b);
        const r = numeric ? x - y : String(x).localeCompare(String(y));
        return ascending ? r : -r;
      });
      for (const r of rows) body.appendChild(r);
    });
  }
}
