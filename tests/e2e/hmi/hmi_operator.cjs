// The operator's controls end to end in real headless Chromium: stencil-sim --speed 5 --hmi on a
// raster job with a journal; on the page six parameter changes (the three limits and the wall's
// damping, friction and speed limiting), a Pause held for a while, Resume,
// then Stop. Checked against the journal (read here, byte by byte, as journal_format.hpp lays it out)
// and the report:
//  - the cycle that took the Stop is the safe state's (its SafeState record, source display), at
//    most one cycle after the request reached the controller's ring; the mill stopped by the next
//    machine update (the report's machine.stopped_s);
//  - while paused no machine command was planned and the virtual tool stayed put; Resume carried
//    on; no gouge, no safe state before the Stop;
//  - the readout on the page at the end matches the report's final positions within 0.001 mm;
//  - stencil-sim --replay of the journal: 0 cycles differ, and its report lists the six changes.
//
//   node hmi_operator.cjs STENCIL_SIM ASSETS_DIR WORK_DIR
// (NODE_PATH must reach the page's node_modules, for playwright-core.)
'use strict';
const { chromium } = require('playwright-core');
const { spawn, spawnSync } = require('child_process');
const fs = require('fs');
const path = require('path');

const [simPath, assetsDir, workDir] = process.argv.slice(2);
if (!simPath || !assetsDir || !workDir) {
  console.error('usage: node hmi_operator.cjs STENCIL_SIM ASSETS_DIR WORK_DIR');
  process.exit(2);
}
fs.rmSync(workDir, { recursive: true, force: true });
fs.mkdirSync(workDir, { recursive: true });
const journalPath = path.join(workDir, 'job.journal');
const reportPath = path.join(workDir, 'report.json');

const UPDATE_NS = 1e9 / 30;  // the machine update (rig_facts.hpp)
const KIND = ['reset', 'stop', 'journal_failed', 'set_coupling', 'set_force_limit', 'set_speed_limit', 'pause', 'resume',
  'set_damping', 'set_friction', 'set_speed_limiting'];
const SOURCE = ['cycle', 'machine', 'program', 'signal', 'terminal', 'display', 'replay', 'control'];

function fail(message) {
  console.error(`FAIL: ${message}`);
  process.exitCode = 1;
  throw new Error(message);
}

// The journal's records (journal_format.hpp): SafeState, MachineCommand and Command read here byte
// by byte (the others, Start, Homed, Provenance and End among them, are stepped over); the cycles,
// compact in Cycles records, through stencil-journal (the controllers' own reader), with the check
// that stands for each cycle's virtual tool.
function readJournal(file) {
  const b = fs.readFileSync(file);
  if (b.toString('latin1', 0, 8) !== 'STENCILJ' || b.readUInt32LE(8) !== 5) {
    fail(`${file}: not a version 5 journal`);
  }
  const out = { cycles: [], safeStates: [], machine: [], commands: [] };
  let at = 12;
  while (at + 9 <= b.length) {
    const length = b.readUInt32LE(at);
    const type = b.readUInt8(at + 4);
    const p = at + 5;
    if (p + length + 4 > b.length) break;
    if (type === 3) {
      out.safeStates.push({ cycle: Number(b.readBigUInt64LE(p)), reason: b.readUInt8(p + 8), source: SOURCE[b.readUInt8(p + 9)] });
    } else if (type === 5) {
      out.machine.push({ update: Number(b.readBigUInt64LE(p)), timeNs: Number(b.readBigInt64LE(p + 8)) });
    } else if (type === 8) {
      out.commands.push({
        cycle: Number(b.readBigUInt64LE(p)), timeNs: Number(b.readBigInt64LE(p + 8)), queued: Number(b.readBigUInt64LE(p + 16)),
        kind: KIND[b.readUInt8(p + 24)], source: SOURCE[b.readUInt8(p + 25)], outcome: b.readUInt8(p + 26),
        asked: b.readDoubleLE(p + 27), applied: b.readDoubleLE(p + 35),
      });
    }
    at = p + length + 4;
  }
  const cycles = spawnSync(path.join(path.dirname(simPath), 'stencil-journal'), ['cycles', file],
    { encoding: 'utf8', maxBuffer: 1 << 30 });
  if (cycles.status !== 0) fail(`stencil-journal cycles ${file}: ${cycles.stderr}`);
  for (const line of cycles.stdout.split('\n')) {
    if (!line) continue;
    const c = JSON.parse(line);
    out.cycles.push({ cycle: c.cycle, tip: c.tip_check });
  }
  return out;
}

function startSim() {
  const sim = spawn(simPath, ['--speed', '5', '--pattern', 'raster', '--duration', '400', '--hmi', '127.0.0.1:0',
    '--hmi-assets', assetsDir, '--journal', journalPath, '--report', reportPath],
  { cwd: workDir, stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '';
  sim.stdout.on('data', (chunk) => { out += chunk; });
  sim.stderr.on('data', (chunk) => { out += chunk; });
  const exited = new Promise((resolve) => sim.on('exit', (code) => resolve(code)));
  const url = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no display URL from stencil-sim within 30 s:\n${out}`)), 30000);
    const look = () => {
      const m = /display: (http:\/\/\S+)/.exec(out);
      if (m) { clearTimeout(timer); resolve(m[1]); } else { setTimeout(look, 100); }
    };
    look();
    sim.on('exit', (code) => reject(new Error(`stencil-sim exited (${code}) before serving:\n${out}`)));
  });
  return { sim, url, exited, output: () => out };
}

const droText = (page, row) => page.$$eval(`#dro-${row} td`, (cells) => cells.map((c) => c.textContent));

async function setParameter(page, input, name, value) {
  if (typeof value === 'string') {
    await page.selectOption(input, value);  // the speed limiting: a select
  } else {
    await page.fill(input, String(value));
  }
  await page.click(`button[data-name="${name}"]`);
  await page.waitForFunction((n) => [...document.querySelectorAll('#events li')].some((li) => li.textContent.includes(`${n} asked`)),
    name, { timeout: 15000 });
}

(async () => {
  const { sim, url, exited, output } = startSim();
  let browser = null;
  let page = null;
  const page_dro = {};
  try {
    const address = await url;
    console.log(`display at ${address}`);
    browser = await chromium.launch({
      executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
      args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
        '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    });
    page = await browser.newPage({ viewport: { width: 1280, height: 1000 } });
    const consoleErrors = [];
    page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
    page.on('pageerror', (e) => consoleErrors.push(String(e)));
    await page.goto(address);
    await page.waitForFunction(() => Number(document.body.dataset.frames || 0) >= 10 && !document.getElementById('stop').disabled,
      null, { timeout: 30000 });
    await page.waitForFunction(() => Number(document.body.dataset.t) > 3, null, { timeout: 30000 });

    // Six parameter changes, each in the event list with the value asked and the value in force: the
    // three limits and the wall's feel (issue 29), which the replay must give back exactly too.
    await setParameter(page, '#coupling', 'coupling', 0.8);
    await setParameter(page, '#force-limit', 'force_limit', 4);
    await setParameter(page, '#speed-limit', 'speed_limit', 0.8);
    await setParameter(page, '#damping', 'damping', 30);
    await setParameter(page, '#friction', 'friction', 0.3);
    await setParameter(page, '#speed-limiting', 'speed_limiting', 'penalty');
    await page.waitForFunction(() => /\(penalty\), damping 30\.0 N s\/m, friction 0\.30/.test(document.getElementById('in-force').textContent),
      null, { timeout: 10000 });
    console.log(`after six changes: ${await page.textContent('#in-force')}`);

    // Pause: the tool and the mill held, on the page too.
    await page.click('#pause');
    await page.waitForFunction(() => document.body.dataset.paused === 'true', null, { timeout: 10000 });
    await page.waitForTimeout(500);
    const toolHeld = await droText(page, 'tool_work');
    const millHeld = await droText(page, 'mill_work');
    const tPaused = Number(await page.evaluate(() => document.body.dataset.t));
    await page.waitForTimeout(2000);
    const tLater = Number(await page.evaluate(() => document.body.dataset.t));
    const toolLater = await droText(page, 'tool_work');
    const millLater = await droText(page, 'mill_work');
    console.log(`paused from ${tPaused} s to ${tLater} s (simulated): tool ${toolHeld} -> ${toolLater}, mill ${millHeld} -> ${millLater}`);
    if (tLater - tPaused < 5) fail(`the job's time did not go on while paused (${tPaused} -> ${tLater})`);
    if (toolLater.join() !== toolHeld.join()) fail('the virtual tool moved while paused');
    if (millLater.join() !== millHeld.join()) fail('the mill moved while paused');
    const stateText = await page.textContent('#safe');
    if (!stateText.startsWith('PAUSED')) fail(`the state does not say paused: '${stateText}'`);

    // Resume: it carries on, with no safe state.
    await page.click('#pause');
    await page.waitForFunction(() => document.body.dataset.paused === 'false', null, { timeout: 10000 });
    await page.waitForTimeout(2000);
    if ((await page.evaluate(() => document.body.dataset.safe)) !== 'none') fail('a safe state after Resume');

    // Stop: the safe state, from the display; the job ends and the page keeps its last state (and
    // tries to reconnect to the display, which went with the job: those refusals are expected).
    const errorsBeforeStop = consoleErrors.length;
    await page.click('#stop');
    await page.waitForFunction(() => document.body.dataset.controller === 'ended' || document.body.dataset.safe === 'stopped',
      null, { timeout: 15000 });
    await page.waitForFunction(() => document.body.dataset.controller !== 'connected', null, { timeout: 30000 });
    await page.waitForTimeout(300);
    for (const row of ['device', 'tool_work', 'tool_machine', 'mill_work', 'mill_machine']) {
      page_dro[row] = (await droText(page, row)).map(Number);
    }
    const events = await page.$$eval('#events li', (items) => items.map((li) => li.textContent));
    console.log(`event list (newest first):\n  ${events.join('\n  ')}`);
    if (!events.some((e) => e.includes('SAFE STATE stopped (from display)'))) fail('the event list has no stop from the display');
    if (!events.some((e) => /pause \(display\): done/.test(e)) || !events.some((e) => /resume \(display\): done/.test(e))) {
      fail('the event list lacks the pause or the resume');
    }
    await page.screenshot({ path: path.join(workDir, 'hmi-operator.png') });
    const unexpected = consoleErrors.filter((e, i) => i < errorsBeforeStop || !e.includes('ERR_CONNECTION_REFUSED'));
    if (unexpected.length > 0) fail(`the page logged errors: ${unexpected.join(' | ')}`);
  } finally {
    if (browser) await browser.close();
    const code = await Promise.race([exited, new Promise((r) => setTimeout(() => r('timeout'), 20000))]);
    if (code === 'timeout') sim.kill('SIGTERM');
    console.log(`stencil-sim exited: ${code}\n${output().split('\n').filter((l) => /safe state|display link|gouge|coverage/.test(l)).join('\n')}`);
  }

  const report = JSON.parse(fs.readFileSync(reportPath, 'utf8'));
  const journal = readJournal(journalPath);

  // The Stop: the request's arrival (queued after cycle q), the cycle that took it (c) and the
  // safe state's record (cycle c, from the display).
  const stop = journal.commands.find((c) => c.kind === 'stop');
  if (!stop) fail('the journal has no Stop record');
  const safe = journal.safeStates[0];
  console.log(`stop: queued after cycle ${stop.queued}, taken by cycle ${stop.cycle} (source ${stop.source}); ` +
    `safe state recorded at cycle ${safe && safe.cycle} from ${safe && safe.source}`);
  if (stop.source !== 'display') fail(`the stop's source is ${stop.source}`);
  if (stop.cycle - stop.queued > 1) fail(`the stop waited ${stop.cycle - stop.queued} cycles`);
  if (journal.safeStates.length !== 1 || safe.cycle !== stop.cycle || safe.source !== 'display') {
    fail(`the safe state is not the stop's cycle's: ${JSON.stringify(journal.safeStates)}`);
  }
  // The mill: stopped by the next machine update (the one under way when the stop came finishes its
  // move first: within two update periods, as the fault cases check), and no machine command planned
  // by an update that began after the stop (a command's time is its update's start + 3 updates).
  const m = report.machine;
  const plannedAfterStop = journal.machine.filter((c) => c.timeNs - 3 * UPDATE_NS > stop.timeNs);
  console.log(`safe state at ${m.safe_state_s} s, mill stopped at ${m.stopped_s} s (simulated); ` +
    `${plannedAfterStop.length} machine commands planned after the stop`);
  if (!(m.stopped_s - m.safe_state_s <= 2 / 30 + 1e-3)) fail('the mill was not stopped by the next machine update');
  if (plannedAfterStop.length !== 0) fail('a machine command was planned after the stop');

  // The pause: no machine command planned while it held, the virtual tool still.
  const pause = journal.commands.find((c) => c.kind === 'pause');
  const resume = journal.commands.find((c) => c.kind === 'resume');
  if (!pause || !resume) fail('the journal lacks the pause or the resume');
  const planned = journal.machine.filter((c) => c.timeNs - 3 * UPDATE_NS > pause.timeNs && c.timeNs - 3 * UPDATE_NS < resume.timeNs);
  const held = journal.cycles.filter((c) => c.cycle >= pause.cycle && c.cycle < resume.cycle);
  const moved = held.filter((c) => c.tip !== held[0].tip);  // the tip's CRC-32: the same tip, the same check
  const after = journal.machine.filter((c) => c.timeNs - 3 * UPDATE_NS > resume.timeNs && c.timeNs - 3 * UPDATE_NS < stop.timeNs);
  console.log(`paused cycles ${pause.cycle}..${resume.cycle}: ${planned.length} machine commands planned, ${moved.length} cycles ` +
    `with the tool moved; after Resume ${after.length} machine commands; machine holds ${report.commands.machine_holds}`);
  if (planned.length !== 0 || moved.length !== 0) fail('the mill or the tool moved while paused');
  if (after.length === 0) fail('nothing was machined after Resume');
  if (report.gouge.max_depth_mm > 0.005) fail(`a gouge of ${report.gouge.max_depth_mm} mm`);
  if (report.safe_state !== 'stopped' || report.commands.safe_state_source !== 'display') {
    fail(`the job ended in ${report.safe_state} from ${report.commands.safe_state_source}`);
  }

  // The readout at the end: the report's final positions within 0.001 mm.
  const f = report.final_positions;
  const expected = { device: f.device_mm, tool_work: f.virtual_tool.work_mm, tool_machine: f.virtual_tool.machine_mm,
    mill_work: f.mill_commanded.work_mm, mill_machine: f.mill_commanded.machine_mm };
  let worst = 0;
  for (const [row, values] of Object.entries(expected)) {
    values.forEach((v, axis) => { worst = Math.max(worst, Math.abs(v - page_dro[row][axis])); });
  }
  console.log(`readout vs report: largest difference ${worst.toFixed(4)} mm over 15 values`);
  if (!(worst <= 0.001)) fail(`the readout differs from the report by ${worst} mm: ${JSON.stringify(page_dro)} vs ${JSON.stringify(expected)}`);

  // Six changes in the report, each with the value asked and applied; the limits from when.
  const changes = report.commands.list.filter((c) => c.parameter);
  console.log(`report: ${changes.map((c) => `${c.parameter} ${c.asked} -> ${c.applied} (${c.outcome}) at ${c.t_s.toFixed(3)} s`).join('; ')}; ` +
    `${report.limits.length} limit sets`);
  if (changes.length !== 6 || report.limits.length !== 7) fail('the report does not list the six changes');
  const last = report.limits[report.limits.length - 1];
  if (last.damping_n_s_per_m !== 30 || last.friction !== 0.3 || last.speed_limiting !== 'penalty') {
    fail(`the limits in force at the end: ${JSON.stringify(last)}`);
  }

  // The replay: the same job, cycle for cycle, with the recorded commands given back.
  const replay = spawnSync(simPath, ['--replay', journalPath, '--report', path.join(workDir, 'replay.json')],
    { cwd: workDir, encoding: 'utf8', timeout: 240000 });
  const lines = (replay.stdout || '').split('\n').filter((l) => l.startsWith('replay'));
  console.log(lines.join('\n'));
  if (replay.status !== 0 || !lines.some((l) => /\(0 taken otherwise\), 0 cycles with a different virtual tool/.test(l))) {
    fail(`the replay differs (exit ${replay.status}): ${replay.stderr}`);
  }
  const replayed = JSON.parse(fs.readFileSync(path.join(workDir, 'replay.json'), 'utf8'));
  const replayedChanges = replayed.commands.list.filter((c) => c.parameter);
  if (replayedChanges.length !== 6) fail(`the replay's report lists ${replayedChanges.length} changes`);
  console.log('PASS');
})().catch((error) => {
  console.error(error.message || error);
  process.exitCode = 1;
});
