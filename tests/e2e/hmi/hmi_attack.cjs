// The display in its own process, attacked while a job runs (issue: the controller keeps cutting
// whatever a browser does). stencil-sim --speed 5 --hmi on a raster job, the page open in headless
// Chromium, then:
//  1. at 10 s the display is killed (SIGKILL) and started again by hand on the same socket and
//     port: the page must show the job again in about a second (checked at 2 s: the machines are shared);
//  2. for 30 s: a WebSocket frame header declaring 2 GiB, 200 connections held open, 50 slow-loris
//     sockets sending one header byte a second (each reconnecting when dropped). Meanwhile the page
//     must keep receiving frames at 15 Hz or more with the coverage rising, and the display's
//     resident memory must stay under 150 MB;
//  3. the controller's peak resident memory (VmHWM) at the end at most its after-setup value plus
//     1 MB, and the job ending with no safe state.
//
//   node hmi_attack.cjs STENCIL_SIM ASSETS_DIR WORK_DIR
// (NODE_PATH must reach the page's node_modules, for playwright-core.)
'use strict';
const { chromium } = require('playwright-core');
const { spawn } = require('child_process');
const fs = require('fs');
const net = require('net');
const path = require('path');

const [simPath, assetsDir, workDir] = process.argv.slice(2);
if (!simPath || !assetsDir || !workDir) {
  console.error('usage: node hmi_attack.cjs STENCIL_SIM ASSETS_DIR WORK_DIR');
  process.exit(2);
}
fs.mkdirSync(workDir, { recursive: true });
const displayPath = path.join(path.dirname(simPath), 'stencil-display');
const failures = [];
function check(ok, message) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${message}`);
  if (!ok) failures.push(message);
}
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
function status(pid, field) {
  try {
    const m = new RegExp(`^${field}:\\s+(\\d+) kB`, 'm').exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
    return m ? Number(m[1]) : NaN;
  } catch (e) {
    return NaN;
  }
}
function waitFor(getText, pattern, what, ms) {
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no ${what} within ${ms / 1000} s:\n${getText()}`)), ms);
    const look = () => {
      const m = pattern.exec(getText());
      if (m) { clearTimeout(timer); resolve(m); } else { setTimeout(look, 50); }
    };
    look();
  });
}

// Attackers. Each keeps its sockets up until stop(): a dropped one is opened again a second later.
function holdConnections(port, count, onData) {
  const sockets = new Set();
  let stopped = false;
  let opened = 0, dropped = 0;
  const open = () => {
    if (stopped) return;
    const s = net.connect(port, '127.0.0.1');
    opened += 1;
    sockets.add(s);
    s.on('error', () => {});
    s.on('close', () => { sockets.delete(s); dropped += 1; if (!stopped) setTimeout(open, 1000); });
    if (onData) onData(s);
  };
  for (let i = 0; i < count; i += 1) open();
  return {
    stop() { stopped = true; for (const s of sockets) s.destroy(); },
    counts: () => ({ opened, dropped, open: sockets.size }),
  };
}
function slowLoris(port, count) {
  const request = `GET / HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nUser-Agent: slow\r\nAccept: */*\r\nX-Padding: ${'a'.repeat(200)}\r\n\r\n`;
  const timers = new Set();
  const held = holdConnections(port, count, (s) => {
    let at = 0;
    const timer = setInterval(() => {
      if (s.destroyed) { clearInterval(timer); timers.delete(timer); return; }
      s.write(request[at % request.length]);
      at += 1;
    }, 1000);
    timers.add(timer);
    s.on('close', () => { clearInterval(timer); timers.delete(timer); });
  });
  return { stop() { for (const t of timers) clearInterval(t); held.stop(); }, counts: held.counts };
}
// A WebSocket upgrade (with this server's Origin), then a frame header declaring 2 GiB and bytes after it.
function hugeFrame(port) {
  return new Promise((resolve) => {
    const s = net.connect(port, '127.0.0.1');
    let upgraded = false, sent = 0;
    const began = Date.now();
    s.on('error', () => {});
    s.on('connect', () => s.write(`GET /ws HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nOrigin: http://127.0.0.1:${port}\r\n` +
      'Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n' +
      'Sec-WebSocket-Version: 13\r\n\r\n'));
    s.on('data', (d) => {
      if (!upgraded && d.toString().startsWith('HTTP/1.1 101')) {
        upgraded = true;
        const header = Buffer.from([0x81, 0xFF, 0, 0, 0, 0, 0x80, 0, 0, 0, 1, 2, 3, 4]);  // FIN text, masked, 2^31 bytes
        s.write(header);
        const chunk = Buffer.alloc(64 * 1024, 0x41);
        const pump = () => { if (!s.destroyed && sent < 64 * 1024 * 1024) { sent += chunk.length; s.write(chunk, pump); } };
        pump();
      }
    });
    s.on('close', () => resolve({ upgraded, sent, closedAfterMs: Date.now() - began }));
    setTimeout(() => { s.destroy(); resolve({ upgraded, sent, closedAfterMs: -1 }); }, 20000);
  });
}

(async () => {
  const report = path.join(workDir, 'report.json');
  const sim = spawn(simPath, ['--speed', '5', '--pattern', 'raster', '--duration', '250', '--hmi', '127.0.0.1:0',
    '--hmi-assets', assetsDir, '--no-journal', '--report', report], { cwd: workDir, stdio: ['ignore', 'pipe', 'pipe'] });
  const simStarted = Date.now();
  let out = '', err = '';
  sim.stdout.on('data', (c) => { out += c; });
  sim.stderr.on('data', (c) => { err += c; });
  const simExit = new Promise((resolve) => sim.on('exit', (code, signal) => resolve({ code, signal })));
  let browser = null, display = null;
  try {
    const [, address, port, displayPid] = await waitFor(() => out, /display: (http:\/\/127\.0\.0\.1:(\d+)\/) \(pid (\d+)/, 'display URL', 30000);
    const [, socketPath] = await waitFor(() => out, /display link: (\S+)/, 'display link', 1000);
    console.log(`display at ${address} (pid ${displayPid}), controller pid ${sim.pid}, socket ${socketPath}`);
    browser = await chromium.launch({
      executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
      args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
        '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    });
    const page = await browser.newPage({ viewport: { width: 1024, height: 700 } });
    await page.goto(address);
    await page.waitForFunction(() => document.body.dataset.part && Number(document.body.dataset.frames || 0) >= 10,
      null, { timeout: 30000 });
    const hwmSetup = status(sim.pid, 'VmHWM');
    console.log(`controller after setup: VmHWM ${hwmSetup} kB`);
    const frames = () => page.evaluate(() => Number(document.body.dataset.frames || 0));
    const coverage = () => page.evaluate(() => Number(document.body.dataset.coverage || 0));

    // 1. At 10 s: the display killed, and started again on the same socket and port.
    await sleep(Math.max(0, 10000 - (Date.now() - simStarted)));
    process.kill(Number(displayPid), 'SIGKILL');
    await sleep(300);
    const framesAtKill = await frames();
    let dout = '';
    display = spawn(displayPath, ['--controller', socketPath, '--listen', `127.0.0.1:${port}`, '--assets', assetsDir],
      { stdio: ['ignore', 'pipe', 'pipe'] });
    display.stdout.on('data', (c) => { dout += c; });
    display.stderr.on('data', (c) => { dout += c; });
    await waitFor(() => dout, /display: http/, 'restarted display', 10000);
    const restarted = Date.now();
    await page.waitForFunction((f0) => Number(document.body.dataset.frames) > f0 + 2 &&
      document.body.dataset.controller === 'connected', framesAtKill, { timeout: 10000, polling: 20 });
    const backMs = Date.now() - restarted;
    // About a second is the goal (the page retries every 200 ms): measured 429, 800 and 1016 ms in three
    // CI runs on these shared machines, so the check is twice that, and the figure is printed.
    check(backMs <= 2000, `the page showed the job again ${backMs} ms after the display was started again (at most 2000)`);

    // 2. The attack, 30 s, while the page is watched second by second.
    const huge = hugeFrame(Number(port));
    const held = holdConnections(Number(port), 200);
    const loris = slowLoris(Number(port), 50);
    const rates = [], coverages = [], times = [], rss = [];
    let lastFrames = await frames();
    let lastTime = Date.now();
    for (let second = 0; second < 30; second += 1) {
      await sleep(1000);
      const f = await frames();
      const now = Date.now();
      rates.push((f - lastFrames) / ((now - lastTime) / 1000));
      lastFrames = f;
      lastTime = now;
      coverages.push(await coverage());
      times.push(await page.evaluate(() => Number(document.body.dataset.t || 0)));
      rss.push(status(display.pid, 'VmRSS'));
    }
    const hugeResult = await huge;
    const heldCounts = held.counts(), lorisCounts = loris.counts();
    held.stop();
    loris.stop();
    // Two-second windows: a frame late by a few ms moves one from one second to the next.
    const windows = [];
    for (let i = 0; i + 1 < rates.length; i += 2) windows.push((rates[i] + rates[i + 1]) / 2);
    const slowest = Math.min(...windows);
    console.log(`frame rate each second: ${rates.map((r) => r.toFixed(0)).join(' ')}`);
    console.log(`coverage: ${coverages.map((c) => (100 * c).toFixed(1)).join(' ')} %`);
    console.log(`display VmRSS: ${rss.map((r) => (r / 1024).toFixed(0)).join(' ')} MB`);
    console.log(`2 GiB frame: upgraded ${hugeResult.upgraded}, ${hugeResult.sent} bytes sent before the close, ` +
      `closed after ${hugeResult.closedAfterMs} ms`);
    console.log(`200 held: ${heldCounts.opened} opened, ${heldCounts.dropped} dropped by the display; ` +
      `50 slow-loris: ${lorisCounts.opened} opened, ${lorisCounts.dropped} dropped`);
    // (`sent` counts what this side queued; the display closed the socket long before reading it.)
    check(hugeResult.upgraded && hugeResult.closedAfterMs >= 0 && hugeResult.closedAfterMs < 2000,
      `the 2 GiB frame header closed its connection at once (${hugeResult.closedAfterMs} ms)`);
    check(slowest >= 15, `the page kept receiving frames at 15 Hz or more (slowest 2 s window ${slowest.toFixed(1)} Hz)`);
    // The baked prism has 9 reachable triangles: its coverage rises in steps of 11 %, not every few
    // seconds. The job's own time shows it going on throughout; the coverage may only rise.
    let advancing = true, neverFell = true;
    for (let i = 1; i < times.length; i += 1) {
      advancing = advancing && times[i] > times[i - 1];
      neverFell = neverFell && coverages[i] >= coverages[i - 1];
    }
    console.log(`simulated time: ${times.map((t) => t.toFixed(0)).join(' ')} s`);
    check(advancing, 'the job went on throughout: its simulated time rose every second on the page');
    check(neverFell && coverages[coverages.length - 1] > coverages[0],
      `the coverage rose over the attack (${(100 * coverages[0]).toFixed(1)} -> ${(100 * coverages[coverages.length - 1]).toFixed(1)} %) and never fell`);
    check(Math.max(...rss) < 150 * 1024, `the display's resident memory stayed under 150 MB (max ${(Math.max(...rss) / 1024).toFixed(1)} MB)`);
    check(lorisCounts.dropped >= 50, 'the slow-loris sockets were dropped');

    // 3. The controller, after all that.
    const hwmEnd = status(sim.pid, 'VmHWM');
    check(hwmEnd <= hwmSetup + 1024, `the controller's VmHWM ${hwmEnd} kB is at most its after-setup ${hwmSetup} kB + 1 MB`);
    const ended = await simExit;
    const result = JSON.parse(fs.readFileSync(report, 'utf8'));
    check(ended.code === 0, `stencil-sim exited ${ended.code}${ended.signal ? ` (${ended.signal})` : ''}`);
    check(result.safe_state === null || result.safe_state === 'none' || result.safe_state === undefined,
      `the job ended with no safe state (${JSON.stringify(result.safe_state)})`);
    console.log(out.split('\n').filter((l) => l.startsWith('display')).join('\n'));
  } catch (error) {
    failures.push(error.message || String(error));
    console.error(error.message || error);
    console.error(out + err);
  } finally {
    if (browser) await browser.close();
    if (display) display.kill('SIGTERM');
    if (sim.exitCode === null) sim.kill('SIGTERM');
  }
  if (failures.length > 0) {
    console.error(`FAIL: ${failures.length} check(s) failed`);
    process.exitCode = 1;
  }
})();
