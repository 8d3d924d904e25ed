// The operator display: the 3-D view, the status, the plots and the parameters, fed by the
// controller's WebSocket (/ws): a snapshot first, then 20 Hz frames of what changed. The page only
// asks; the server and the cycle decide (refusals come back with their reason).
import { connect } from './connection.js';
import { Scene } from './scene.js';
import { drawHistogram, ForcePlot } from './plots.js';
import { clearEvents, showEvents, showReadout } from './readout.js';

const $ = (id) => document.getElementById(id);
const scene = new Scene($('view'));
const forcePlot = new ForcePlot($('force-plot'), 10.0);
let mayControl = false;
let limits = null;
let last = null;
let framesSeen = 0;
let partJob = null;  // the job whose part is shown: a new controller's job brings its own part
let partLoading = false;

function fixed(value, digits) { return value === null || value === undefined ? '–' : Number(value).toFixed(digits); }

// The controller this display watches: none yet, live, or ended (with how, and its last state).
function showController(controller) {
  const c = $('controller');
  if (!controller) {
    return;
  }
  if (controller.ended) {
    c.textContent = `job ended: ${controller.end || 'the controller stopped'} (last state shown)`;
    c.className = 'state-warn';
  } else if (controller.state === 'connected') {
    c.textContent = `controller: ${controller.detail}`;
    c.className = 'state-ok';
  } else if (controller.state === 'ended') {
    c.textContent = `controller gone: ${controller.detail} (last state shown)`;
    c.className = 'state-warn';
  } else {
    c.textContent = controller.state === 'refused' ? `controller refused: ${controller.detail}`
      : `no controller: ${controller.detail}`;
    c.className = 'state-bad';
  }
  document.body.dataset.controller = controller.ended ? 'ended' : controller.state;
  if (controller.job && controller.job !== '0' && controller.job !== partJob && !partLoading) {
    clearEvents();
    loadPart(controller.job);
  }
}

function loadPart(job) {
  partLoading = true;
  fetch('/api/part').then((r) => (r.ok ? r.json() : null)).then((part) => {
    partLoading = false;
    if (part === null) {
      return;
    }
    scene.setPart(part);
    partJob = part.job;
    document.body.dataset.part = String(part.triangles);
    document.body.dataset.job = String(part.job);
  }).catch(() => { partLoading = false; });
  return job;
}

function showState(message) {
  $('coverage').textContent = `${fixed(message.coverage * 100, 1)} %  (${message.touched_count} triangles)`;
  $('time').textContent = `${fixed(message.t, 1)} s, cycle ${message.cycle}`;
  $('lag').textContent = `${fixed(message.lag_mm, 3)} mm`;
  const f = message.force;
  $('force').textContent = `${fixed(Math.hypot(f[0], f[1], f[2]), 2)} N`;
  const safe = message.safe;
  const state = $('safe');
  state.textContent = safe.active ? `SAFE STATE: ${safe.reason}` : 'cutting';
  state.className = safe.active ? 'state-bad' : 'state-ok';
  if (safe.active) {
    state.textContent += ` (from ${safe.source})`;
  } else if (message.paused) {
    state.textContent = 'PAUSED: the tool and the mill are held';
    state.className = 'state-warn';
  }
  const live = mayControl && message.controller && message.controller.state === 'connected' && !message.controller.ended;
  $('stop').disabled = !live;
  const pause = $('pause');
  pause.textContent = message.paused ? 'Resume' : 'Pause';
  pause.dataset.request = message.paused ? 'resume' : 'pause';
  pause.disabled = !(live && !safe.active);
  document.body.dataset.paused = String(Boolean(message.paused));
  document.body.dataset.safe = safe.active ? safe.reason : 'none';
  showReadout(message.dro);
  showEvents(message.events);
  const reset = $('reset');
  reset.disabled = !(mayControl && safe.active && safe.reset_allowed);
  $('reset-reason').textContent = safe.active
    ? (safe.reset_allowed ? 'reset allowed: the handle is still, near the tool' : `reset: ${safe.reset_refusal}`)
    : (safe.reset_requests > 0 ? `last reset: ${safe.last_reset}` : '');
  const p = message.params;
  $('in-force').textContent = `in force: coupling ${fixed(p.coupling, 2)} N/mm, force limit ${fixed(p.force_limit, 2)} N, ` +
    `speed limit ${p.speed_limit === null ? 'unlimited' : fixed(p.speed_limit, 2) + ' mm/s'} (${p.speed_limiting}), ` +
    `damping ${fixed(p.damping, 1)} N s/m, friction ${fixed(p.friction, 2)}` +
    (p.requests > 0 ? ` (last change ${p.last}: ${p.last_outcome})` : '');
  for (const [id, key] of [['coupling', 'coupling'], ['force-limit', 'force_limit'], ['speed-limit', 'speed_limit'],
    ['damping', 'damping'], ['friction', 'friction'], ['speed-limiting', 'speed_limiting']]) {
    const input = $(id);
    if (document.activeElement !== input && input.dataset.edited !== '1' && p[key] !== null) {
      input.value = p[key];
    }
  }
  if (message.loop) {
    drawHistogram($('wakeup-plot'), message.loop.wakeup, 'us');
    drawHistogram($('compute-plot'), message.loop.compute, 'us');
  }
  const s = message.server;
  $('server').textContent = `display: ${s.clients} client(s), ${s.frames_dropped} frames dropped for slow clients, ` +
    `${s.malformed} malformed, ${s.refused} refused, ${s.connections_refused} connections refused`;
}

function onMessage(message) {
  switch (message.type) {
    case 'hello':
      mayControl = message.may_control;
      for (const button of document.querySelectorAll('#params button')) {
        button.disabled = !mayControl;
      }
      if (!mayControl) {
        $('param-message').textContent = message.reason;
      }
      break;
    case 'waiting':
      showController(message.controller);
      break;
    case 'snapshot':
      limits = message.limits;
      scene.setStock(message.stock_grid);
      scene.setTouched(message.touched, true);
      forcePlot.restart(message.t);
      // falls through: the rest is as in a frame
    case 'frame':
      if (message.type === 'frame') {
        if (last !== null && message.seq !== last.seq + 1) {
          console.warn(`frame ${message.seq} after ${last.seq}: waiting for the snapshot`);
        }
        if (message.stock_grid) {
          scene.setStock(message.stock_grid);
        }
        scene.updateStock(message.stock);
        scene.setTouched(message.touched, false);
      }
      showController(message.controller);
      $('clock-note').textContent = message.virtual_clock
        ? 'virtual clock (--fast or --speed N): the loop\'s wake-up latency and compute time are 0 by construction'
        : '';
      scene.setTool(message.tool, message.probe, message.force);
      forcePlot.add(message.t, Math.max(message.force_peak, Math.hypot(...message.force)));
      showState(message);
      last = message;
      framesSeen += 1;
      document.body.dataset.frames = String(framesSeen);
      document.body.dataset.coverage = String(message.coverage);
      document.body.dataset.t = String(message.t);
      break;
    case 'accepted': {
      const where = message.request === 'set' ? $('param-message') : $('machine-message');
      where.textContent = `${message.name ?? message.request}: sent to the cycle`;
      where.className = 'note state-ok';
      break;
    }
    case 'refused': {
      const parameter = message.request === 'set' || !message.request;
      const where = parameter ? $('param-message') : $('machine-message');
      where.textContent = parameter ? `refused: ${message.reason}` : `${message.request} refused: ${message.reason}`;
      where.className = 'note state-bad';
      break;
    }
    case 'error':
      $('param-message').textContent = `error: ${message.error}`;
      $('param-message').className = 'note state-bad';
      break;
    default:
      break;
  }
}

const token = new URLSearchParams(window.location.search).get('token');
const link = connect(`/ws${token ? `?token=${encodeURIComponent(token)}` : ''}`, onMessage, (state) => {
  const c = $('connection');
  c.textContent = state;
  c.className = state === 'live' ? 'state-ok' : 'state-warn';
});

for (const button of document.querySelectorAll('#params button')) {
  button.addEventListener('click', () => {
    const input = button.parentElement.querySelector('input, select');
    input.dataset.edited = '';
    // A select (the speed limiting) sends its value's name, an input its number.
    const value = input.tagName === 'SELECT' ? input.value : Number(input.value);
    link.send({ type: 'set', name: button.dataset.name, value });
  });
}
for (const input of document.querySelectorAll('#params input, #params select')) {
  input.addEventListener('input', () => { input.dataset.edited = '1'; });
}
$('reset').addEventListener('click', () => link.send({ type: 'reset' }));
$('stop').addEventListener('click', () => link.send({ type: 'stop' }));
$('pause').addEventListener('click', () => link.send({ type: $('pause').dataset.request || 'pause' }));


// For the end-to-end test and for anyone curious: how much of the view is not background.
window.hmiPixelStats = () => scene.pixelStats();
