// The position readout (a machine's DRO: the device, the virtual tool and the mill's last
// commanded position, in work and machine coordinates) and the event list (what the cycle did with
// each command, and each safe state with where it came from), as the controller's frames give them.

const DRO_ROWS = ['device', 'tool_work', 'tool_machine', 'mill_work', 'mill_machine'];

// Millimetres to the micrometre, as a DRO shows them.
function mm(value) { return value === null || value === undefined ? '–' : Number(value).toFixed(3); }

export function showReadout(dro) {
  if (!dro) {
    return;
  }
  for (const row of DRO_ROWS) {
    const cells = document.querySelectorAll(`#dro-${row} td`);
    const values = dro[row] || [];
    cells.forEach((cell, axis) => { cell.textContent = mm(values[axis]); });
  }
  const held = document.getElementById('dro-mill_work').querySelector('th');
  held.textContent = dro.mill_held ? 'mill, work (HELD)' : 'mill, work';
}

function describe(event) {
  const when = `${Number(event.t).toFixed(3)} s`;
  if (event.type === 'safe_state') {
    return { text: `${when}  SAFE STATE ${event.reason} (from ${event.source})`, tone: 'bad' };
  }
  let what = event.type;
  if (event.parameter) {
    // The speed limiting is a choice, 0 or 1 on the wire: said by its name.
    const value = (v) => (v === null ? 'unlimited'
      : event.parameter === 'speed_limiting' ? ({ 0: 'cap', 1: 'penalty' }[v] ?? String(v)) : Number(v).toPrecision(4));
    const applied = value(event.applied);
    const asked = value(event.asked);
    what = `${event.parameter} asked ${asked}, in force ${applied}`;
  }
  const ok = event.outcome === 'done';
  return { text: `${when}  ${what} (${event.source}): ${event.outcome}`, tone: ok ? '' : 'warn' };
}

// Newest first; only the events not shown yet are added, so the list keeps what scrolled past.
let shown = -1;
export function showEvents(events) {
  if (!Array.isArray(events)) {
    return;
  }
  const list = document.getElementById('events');
  for (const event of events) {
    if (event.n <= shown) {
      continue;
    }
    const item = document.createElement('li');
    const { text, tone } = describe(event);
    item.textContent = text;
    item.value = event.n + 1;
    item.dataset.type = event.type;
    if (tone) {
      item.className = tone;
    }
    list.prepend(item);
    shown = event.n;
  }
  while (list.children.length > 200) {
    list.lastElementChild.remove();
  }
}

// A new job starts a new list.
export function clearEvents() {
  shown = -1;
  document.getElementById('events').replaceChildren();
}
