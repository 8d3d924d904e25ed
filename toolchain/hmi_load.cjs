// A load on the operator display, for measuring (not a test): one page in headless Chromium that
// counts its frames, and STALLED raw clients that shake hands and then never read a byte.
//   node toolchain/hmi_load.cjs URL SECONDS STALLED
// (NODE_PATH must reach build/hmi-npm/node_modules, for playwright-core.) Prints what the page saw.
'use strict';
const { chromium } = require('playwright-core');
const net = require('net');

const [url, seconds, stalledCount] = [process.argv[2], Number(process.argv[3] || 30), Number(process.argv[4] || 1)];
(async () => {
  const { hostname, port } = new URL(url);
  const stalled = [];
  for (let i = 0; i < stalledCount; i += 1) {
    const socket = net.connect({ host: hostname, port: Number(port) }, () => {
      // A browser's upgrade (the display refuses one without its own Origin), then never a read.
      socket.write(`GET /ws HTTP/1.1\r\nHost: ${hostname}:${port}\r\nOrigin: http://${hostname}:${port}\r\n` +
        'Upgrade: websocket\r\nConnection: Upgrade\r\n' +
        'Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n');
      socket.pause();  // and never read
    });
    socket.on('error', () => {});
    stalled.push(socket);
  }
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
      '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(url);
  await page.waitForFunction(() => Number(document.body.dataset.frames || 0) > 0, null, { timeout: 30000 });
  const f0 = Number(await page.evaluate(() => document.body.dataset.frames));
  const t0 = Date.now();
  await page.waitForTimeout(seconds * 1000);
  const f1 = Number(await page.evaluate(() => document.body.dataset.frames));
  const dt = (Date.now() - t0) / 1000;
  console.log(`page: ${f1 - f0} frames in ${dt.toFixed(1)} s = ${((f1 - f0) / dt).toFixed(1)} Hz; ${stalledCount} stalled client(s)`);
  await browser.close();
  stalled.forEach((s) => s.destroy());
})().catch((e) => { console.error(e); process.exit(1); });
