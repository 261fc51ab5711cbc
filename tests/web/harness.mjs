// What the browser tests and scripts/figures-web share: a fishtank-server with
// its web port, and Debian's chromium driven by puppeteer-core (which downloads
// no browser), headless with SwiftShader's software WebGL.
//
// Environment: FISHTANK_SERVER (the server binary), FISHTANK_WEB_DIR (web/,
// whose node_modules hold puppeteer-core), CHROMIUM (the browser; default: chromium on PATH).

import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

export function need(name) {
  const value = process.env[name];
  if (!value) throw new Error(`${name} is not set (tests/web/CMakeLists.txt sets it; see tests/web/harness.mjs)`);
  return value;
}

export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// Starts fishtank-server with --port 0 and the given web port (0: a free one) and
// resolves once it prints "web viewer on http://ADDR:PORT/".
export function startServer(args = [], webPort = 0) {
  const child = spawn(need('FISHTANK_SERVER'), ['--port', '0', '--web-port', String(webPort), ...args],
                      { stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => fail(new Error(`no "web viewer on" line within 20 s:\n${output}`)), 20000);
    const fail = (e) => {
      clearTimeout(timer);
      child.kill('SIGKILL');
      reject(e);
    };
    const read = (chunk) => {
      output += chunk;
      const m = output.match(/web viewer on (http:\/\/[^\s]+\/)/);
      if (!m) return;
      clearTimeout(timer);
      const url = new URL(m[1]);
      if (url.hostname === '0.0.0.0') url.hostname = '127.0.0.1';
      resolve({
        url: url.href,
        port: Number(url.port),
        output: () => output,
        stop: () => new Promise((done) => {
          if (child.exitCode !== null || child.signalCode !== null) return done();
          child.once('exit', done);
          child.kill('SIGTERM');
        }),
      });
    };
    child.stdout.on('data', read);
    child.stderr.on('data', read);
    child.once('exit', (code) => fail(new Error(`fishtank-server exited (${code}) before serving the page:\n${output}`)));
  });
}

// puppeteer-core wants a path, not a name to look up.
function chromium() {
  if (process.env.CHROMIUM) return process.env.CHROMIUM;
  for (const dir of (process.env.PATH || '').split(path.delimiter)) {
    const candidate = path.join(dir, 'chromium');
    if (fs.existsSync(candidate)) return candidate;
  }
  throw new Error('no chromium on PATH: scripts/install-deps browser installs Debian\'s, or set CHROMIUM');
}

export async function launchBrowser(width = 800, height = 600) {
  const require = createRequire(path.join(need('FISHTANK_WEB_DIR'), 'package.json'));
  const puppeteer = require('puppeteer-core');
  // /tmp, not /dev/shm, for shared memory: containers often give /dev/shm 64 MiB.
  const args = ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-dev-shm-usage',
                `--window-size=${width},${height}`];
  // Chromium's sandbox refuses to start as root.
  if (process.getuid?.() === 0) args.push('--no-sandbox');
  // headless: true is Chromium's new headless mode (--headless=new).
  return puppeteer.launch({
    executablePath: chromium(),
    headless: true,
    args,
    defaultViewport: { width, height },
  });
}

// Polls the page's window.fishtank.state() until pred holds; returns that state.
export async function waitForState(page, pred, what, timeoutMs = 15000) {
  const deadline = Date.now() + timeoutMs;
  let state = null;
  while (Date.now() < deadline) {
    state = await page.evaluate(() => window.fishtank?.state() ?? null);
    if (state && pred(state)) return state;
    await sleep(100);
  }
  throw new Error(`waited ${timeoutMs / 1000} s for ${what}; the page's state: ${JSON.stringify(state)}`);
}

// Counts the screenshot's pixels by colour, in the page (a PNG decoder it already has):
// shaded spheres span dark to bright versions of their colour, so a pixel counts for
// a colour when that channel is bright enough and clearly dominates
// (tests/viewer/screenshot_check.cpp's rule).
export async function countColours(page, png) {
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const n = { red: 0, green: 0, blue: 0, white: 0, amber: 0, background: 0, total: c.width * c.height };
    const [br, bg, bb] = [d[0], d[1], d[2]];  // the corner: the clear colour
    for (let i = 0; i < d.length; i += 4) {
      const r = d[i], g = d[i + 1], b = d[i + 2];
      const lo = Math.min(r, g, b), hi = Math.max(r, g, b);
      if (Math.abs(r - br) <= 6 && Math.abs(g - bg) <= 6 && Math.abs(b - bb) <= 6) ++n.background;
      else if (lo >= 170 && hi - lo <= 30) ++n.white;
      else if (r >= 150 && r > g && g >= 0.4 * r && b <= 0.65 * g) ++n.amber;  // the own sphere's ring
      else if (r >= 80 && r > 2 * g && r > 2 * b) ++n.red;
      else if (g >= 80 && g > 2 * r && g > 2 * b) ++n.green;
      else if (b >= 80 && b > 2 * r && b > 1.5 * g) ++n.blue;
    }
    return n;
  }, Buffer.from(png).toString('base64'));
}
