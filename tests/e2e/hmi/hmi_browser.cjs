// The operator display end to end in real headless Chromium (Debian's, driven by playwright-core):
// stencil-sim --speed 5 --hmi on a raster job, the page opened, the part rendered (a screenshot
// saved and checked to be more than background), the coverage seen to rise, the coupling changed
// and applied by the cycle, a 50 N force limit refused with the reason.
//
//   node hmi_browser.cjs STENCIL_SIM ASSETS_DIR WORK_DIR
// (NODE_PATH must reach the page's node_modules, for playwright-core.)
'use strict';
const { chromium } = require('playwright-core');
const { spawn } = require('child_process');
const fs = require('fs');
const path = require('path');

const [simPath, assetsDir, workDir] = process.argv.slice(2);
if (!simPath || !assetsDir || !workDir) {
  console.error('usage: node hmi_browser.cjs STENCIL_SIM ASSETS_DIR WORK_DIR');
  process.exit(2);
}
fs.mkdirSync(workDir, { recursive: true });

function fail(message) {
  console.error(`FAIL: ${message}`);
  process.exitCode = 1;
  throw new Error(message);
}

function startSim() {
  const sim = spawn(simPath, ['--speed', '5', '--pattern', 'raster', '--duration', '400', '--hmi', '127.0.0.1:0',
    '--hmi-assets', assetsDir, '--no-journal', '--report', path.join(workDir, 'report.json')],
  { cwd: workDir, stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '';
  sim.stdout.on('data', (chunk) => { out += chunk; });
  sim.stderr.on('data', () => {});
  const url = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no display URL from stencil-sim within 30 s:\n${out}`)), 30000);
    const look = () => {
      const m = /display: (http:\/\/\S+)/.exec(out);
      if (m) { clearTimeout(timer); resolve(m[1]); } else { setTimeout(look, 100); }
    };
    look();
    sim.on('exit', (code) => reject(new Error(`stencil-sim exited (${code}) before serving:\n${out}`)));
  });
  return { sim, url, output: () => out };
}

(async () => {
  const { sim, url, output } = startSim();
  let browser = null;
  try {
    const address = await url;
    console.log(`display at ${address}`);
    browser = await chromium.launch({
      executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
      args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
        '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    });
    const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
    const consoleErrors = [];
    page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
    page.on('pageerror', (e) => consoleErrors.push(String(e)));
    await page.goto(address);
    await page.waitForFunction(() => document.body.dataset.part && Number(document.body.dataset.frames || 0) >= 10,
      null, { timeout: 30000 });
    await page.waitForTimeout(1000);

    // The part rendered: more than background in the 3-D view, and in several colours.
    const pixels = await page.evaluate(() => window.hmiPixelStats());
    const shot = path.join(workDir, 'hmi-screenshot.png');
    await page.screenshot({ path: shot });
    console.log(`view ${pixels.width}x${pixels.height}: ${pixels.foreground} pixels not background, ` +
      `${pixels.colours} colours sampled; screenshot ${shot} (${fs.statSync(shot).size} bytes)`);
    if (pixels.foreground < 0.01 * pixels.width * pixels.height || pixels.colours < 4) {
      fail('the 3-D view is blank');
    }

    // --speed 5 is the virtual clock: the page says what that means for the loop plots.
    const clockNote = await page.textContent('#clock-note');
    if (!clockNote.includes('virtual clock')) {
      fail(`the page does not say the loop timing is on a virtual clock: '${clockNote}'`);
    }

    // The coverage figure rises as the raster touches the part.
    const coverageText = () => page.textContent('#coverage');
    const startCoverage = Number(await page.evaluate(() => document.body.dataset.coverage));
    const startText = await coverageText();
    const began = Date.now();
    await page.waitForFunction((c0) => Number(document.body.dataset.coverage) > c0, startCoverage, { timeout: 120000 });
    const laterText = await coverageText();
    console.log(`coverage: '${startText}' -> '${laterText}' after ${((Date.now() - began) / 1000).toFixed(1)} s`);
    if (laterText === startText) {
      fail('the coverage figure on the page did not change');
    }

    // The coupling: asked, sent to the cycle, applied there.
    await page.fill('#coupling', '0.8');
    await page.click('button[data-name="coupling"]');
    await page.waitForFunction(() => document.getElementById('param-message').textContent.includes('sent to the cycle'),
      null, { timeout: 10000 });
    await page.waitForFunction(() => /coupling 0\.80 N\/mm.*coupling: applied/.test(document.getElementById('in-force').textContent),
      null, { timeout: 10000 });
    console.log(`coupling: ${await page.textContent('#in-force')}`);

    // 50 N: refused by the server with the reason; the cycle's limit stays 5 N.
    await page.fill('#force-limit', '50');
    await page.click('button[data-name="force_limit"]');
    await page.waitForFunction(() => document.getElementById('param-message').textContent.startsWith('refused'),
      null, { timeout: 10000 });
    const refusal = await page.textContent('#param-message');
    console.log(`force limit 50 N: ${refusal}`);
    if (!refusal.includes("above the board's force limit of 5 N")) {
      fail(`the refusal does not give the reason: '${refusal}'`);
    }
    await page.waitForTimeout(500);
    const inForce = await page.textContent('#in-force');
    if (!inForce.includes('force limit 5.00 N')) {
      fail(`the force limit changed: '${inForce}'`);
    }

    // A malformed message is answered with an error, and the page stays live.
    const answer = await page.evaluate(() => new Promise((resolve) => {
      const ws = new WebSocket(`ws://${location.host}/ws`);
      ws.onmessage = (e) => { const m = JSON.parse(e.data); if (m.type === 'error') { resolve(m.error); ws.close(); } };
      ws.onopen = () => ws.send('{"type": "set", "name": "force_limit"');
      setTimeout(() => resolve('no answer'), 5000);
    }));
    console.log(`malformed message: ${answer}`);
    if (!answer.startsWith('not JSON')) {
      fail(`a malformed message was not answered with an error: '${answer}'`);
    }
    await page.screenshot({ path: shot });
    if (consoleErrors.length > 0) {
      fail(`the page logged errors: ${consoleErrors.join(' | ')}`);
    }
  } finally {
    if (browser) await browser.close();
    sim.kill('SIGTERM');
    await new Promise((resolve) => { if (sim.exitCode !== null) resolve(); else sim.on('exit', resolve); });
    const served = /display: .*/g;
    for (const line of output().match(served) || []) console.log(line);
  }
})().catch((error) => {
  console.error(error.message || error);
  process.exitCode = 1;
});
