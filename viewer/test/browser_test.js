#!/usr/bin/env node
// Headless-browser test of an `nhdyn view` page (puppeteer-core driving Debian's chromium).
//
//   node test/browser_test.js PAGE.html [--out DIR] [--run K] [--times t1,t2,t3] [--screenshot-at t]
//       the page loads (file://) with no console error, no page error, no request for
//       anything but the page itself; window.nhdyn.ready resolves; at three times (sample
//       times of run K: its first, middle and three-quarter sample, or --times) it dumps
//       nhdyn.linkPoses() with the q it used to DIR/poses.json; screenshots of the 3D view at
//       two times (DIR/shot-1.png, DIR/shot-2.png) must differ, and the second must show the
//       base's trace; prints the page's size and load time.
//   node test/browser_test.js --missing-mesh PAGE.html [--out DIR]
//       the page (of a URDF with a mesh that is not embedded) loads with no console error,
//       and shows the notice line; stand-ins are drawn.
//
// Environment: CHROMIUM (default /usr/bin/chromium). Exit status 0 when every check passed.
'use strict';
const fs = require('fs');
const path = require('path');
const url = require('url');
const puppeteer = require('puppeteer-core');

function parseArgs(argv) {
  const a = { page: null, out: null, run: 0, times: null, missingMesh: false, shotAt: null };
  for (let i = 0; i < argv.length; i++) {
    const x = argv[i];
    if (x === '--out') a.out = argv[++i];
    else if (x === '--run') a.run = Number(argv[++i]);
    else if (x === '--times') a.times = argv[++i].split(',').map(Number);
    else if (x === '--screenshot-at') a.shotAt = Number(argv[++i]);
    else if (x === '--missing-mesh') a.missingMesh = true;
    else if (x === '-h' || x === '--help') { console.log(fs.readFileSync(__filename, 'utf8').split('\n').slice(1, 16).join('\n')); process.exit(0); }
    else if (!a.page) a.page = x;
    else throw new Error('unexpected argument ' + x);
  }
  if (!a.page) throw new Error('usage: node test/browser_test.js [--missing-mesh] PAGE.html [--out DIR]');
  a.out = a.out || path.join(__dirname, '..', 'out', 'test-' + path.basename(a.page, '.html'));
  return a;
}

let passed = 0, failed = 0;
function check(ok, what, detail) {
  if (ok) { passed++; console.log('ok - ' + what + (detail ? ' (' + detail + ')' : '')); }
  else { failed++; console.log('not ok - ' + what + (detail ? ' (' + detail + ')' : '')); }
  return ok;
}

async function main() {
  const a = parseArgs(process.argv.slice(2));
  const pagePath = path.resolve(a.page);
  const pageUrl = url.pathToFileURL(pagePath).href;
  fs.mkdirSync(a.out, { recursive: true });
  const size = fs.statSync(pagePath).size;

  const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--disable-gpu-driver-bug-workarounds', '--window-size=1280,800'],
  });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 800, deviceScaleFactor: 1 });
    const consoleErrors = [], requests = [];
    page.on('console', (m) => {
      if (m.type() === 'error') consoleErrors.push(m.text());
      else if (m.type() === 'warn' || m.type() === 'warning') console.log('  (console warning) ' + m.text().slice(0, 300));
    });
    page.on('pageerror', (e) => consoleErrors.push('page error: ' + (e && e.message ? e.message : e)));
    page.on('request', (r) => { if (r.url() !== pageUrl && !/^(data|blob):/.test(r.url())) requests.push(r.url()); });

    const t0 = Date.now();
    await page.goto(pageUrl, { waitUntil: 'load', timeout: 60000 });
    const ready = await page.evaluate(() => window.nhdyn.ready.then(() => ({ ok: true }), (e) => ({ ok: false, error: String(e) })));
    const loadMs = Date.now() - t0;
    const inPage = await page.evaluate(() => ({ readyTime: window.nhdyn.readyTime, timings: window.nhdyn.timings, nav: performance.getEntriesByType('navigation').map((e) => ({ responseEnd: e.responseEnd, domInteractive: e.domInteractive, loadEventEnd: e.loadEventEnd }))[0], errors: window.nhdyn.errors, notices: window.nhdyn.notices, state: window.nhdyn.state ? window.nhdyn.state() : null }));
    check(ready.ok, 'window.nhdyn.ready resolved', ready.error);
    console.log(`page: ${pagePath}`);
    console.log(`size: ${(size / 1e6).toFixed(2)} MB (${size} bytes)`);
    console.log(`load: ${loadMs} ms from navigation to nhdyn.ready in the test, ${Math.round(inPage.readyTime)} ms in the page (performance.now at ready)`);
    console.log(`timings (ms since navigation start): ${JSON.stringify(Object.fromEntries(Object.entries({ ...inPage.nav, ...inPage.timings }).map(([k, v]) => [k, Math.round(v)])))}`);
    if (inPage.state) console.log(`state: ${JSON.stringify(inPage.state)}`);
    check(inPage.errors.length === 0, 'nhdyn.errors is empty', inPage.errors.join('; '));
    if (!ready.ok) throw new Error('the page did not get ready: ' + ready.error + (consoleErrors.length ? '; console: ' + consoleErrors.join(' | ') : ''));
    check(!!(inPage.state && inPage.state.webgl), 'WebGL renderer created');

    const viewClip = await page.evaluate(() => {
      const r = document.getElementById('view').getBoundingClientRect();
      return { x: Math.round(r.x), y: Math.round(r.y), width: Math.round(r.width), height: Math.round(r.height) };
    });

    if (a.missingMesh) {
      const n = await page.evaluate(() => {
        const e = document.getElementById('notice');
        const cs = getComputedStyle(e);
        return { text: e.textContent, visible: !e.hidden && cs.display !== 'none' && cs.visibility !== 'hidden' && e.offsetHeight > 0,
          lines: Math.round(e.scrollHeight / parseFloat(cs.lineHeight || '16')) };
      });
      check(n.visible && /mesh/.test(n.text), 'the notice line is shown', JSON.stringify(n.text));
      check(inPage.state && inPage.state.standIns > 0, 'stand-ins are drawn', inPage.state && `${inPage.state.standIns} stand-in(s)`);
      await page.screenshot({ path: path.join(a.out, 'missing-mesh.png'), clip: viewClip });
      console.log(`screenshot: ${path.join(a.out, 'missing-mesh.png')}`);
    } else {
      // Link poses at three sample times.
      const runInfo = await page.evaluate((k) => {
        const r = window.NHDYN_DATA.runs[k];
        return { name: r.name, t: r.t, joint_names: window.NHDYN_DATA.robot.joint_names };
      }, a.run);
      await page.evaluate((k) => window.nhdyn.setRun(k), a.run);
      const n = runInfo.t.length;
      const times = a.times || [...new Set([0, Math.floor(n / 2), Math.floor(3 * n / 4)])].map((i) => runInfo.t[i]);
      const samples = [];
      for (const t of times) {
        const s = await page.evaluate((tt) => {
          const used = window.nhdyn.setTime(tt);
          return { t: used, q: window.nhdyn.q(), poses: window.nhdyn.linkPoses() };
        }, t);
        samples.push({ t: s.t, index: runInfo.t.indexOf(s.t), q: s.q, poses: s.poses });
      }
      const posesFile = path.join(a.out, 'poses.json');
      fs.writeFileSync(posesFile, JSON.stringify({
        page: pagePath, run: runInfo.name, joint_names: runInfo.joint_names,
        note: 'poses: link name -> world matrix, 16 numbers, column-major (three.js Matrix4.elements), metres, the URDF world frame',
        samples,
      }, null, 1));
      // A run that names the link carrying its task point: the page's pose of that link
      // must put the point where nhdyn's CSV says r is (r is written to 0.1 um in the page).
      const task = await page.evaluate((k) => { const t = window.NHDYN_DATA.runs[k].task || {}; return { frame: t.frame, point: t.point || [0, 0, 0], path: t.frame ? t.path : null }; }, a.run);
      if (task.frame && task.path) {
        let worst = 0;
        for (const s of samples) {
          const m = s.poses[task.frame], p = task.point, r = task.path[s.index];
          if (!m || !r) { worst = Infinity; break; }
          for (let i = 0; i < 3; i++) worst = Math.max(worst, Math.abs(m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i] - r[i]));
        }
        check(worst < 2e-7, `the pose of '${task.frame}' puts the task point on the run's r`, `largest difference ${worst.toExponential(2)} m`);
      }
      const nLinks = Object.keys(samples[0].poses).length;
      const finite = samples.every((s) => Object.values(s.poses).every((m) => m.length === 16 && m.every(Number.isFinite)));
      check(nLinks > 0 && finite, 'linkPoses() gives finite 4x4 matrices', `${nLinks} links at ${times.length} times -> ${posesFile}`);

      // Screenshots at two times: the robot moved, the trace is drawn.
      if (n === 1) {
        const file = path.join(a.out, 'shot-1.png');
        await page.screenshot({ path: file, clip: viewClip });
        console.log(`screenshot: ${file} (a single pose)`);
      }
      if (n > 1) {
        const ta = runInfo.t[0], tb = a.shotAt != null ? a.shotAt : runInfo.t[Math.floor(n / 2)];
        const shots = [];
        for (const [k, t] of [[1, ta], [2, tb]]) {
          await page.evaluate((tt) => { window.nhdyn.setTime(tt); window.nhdyn.render(); }, t);
          const file = path.join(a.out, `shot-${k}.png`);
          const png = await page.screenshot({ path: file, clip: viewClip });
          shots.push(Buffer.from(png).toString('base64'));
          console.log(`screenshot: ${file} (t = ${t} s)`);
        }
        const full = path.join(a.out, 'page.png');
        await page.screenshot({ path: full });
        console.log(`screenshot: ${full} (the whole page)`);
        const traceColor = await page.evaluate(() => window.nhdyn.traceColor);
        const cmp = await compareImages(browser, shots[0], shots[1], traceColor);
        const frac = cmp.differ / cmp.total;
        check(frac > 0.002, 'the screenshots at two times differ', `${cmp.differ} of ${cmp.total} pixels (${(100 * frac).toFixed(2)} %)`);
        const tracePoints = await page.evaluate(() => window.nhdyn.state().tracePoints);
        if (tracePoints > 0) {
          // The trace alone (robot hidden, so that the base cannot cover it) at the last time.
          const file = path.join(a.out, 'trace.png');
          await page.evaluate((tt) => { window.nhdyn.setTime(tt); window.nhdyn.setVisible({ robot: false }); }, runInfo.t[n - 1]);
          const png = await page.screenshot({ path: file, clip: viewClip });
          await page.evaluate((tt) => { window.nhdyn.setVisible({ robot: true }); window.nhdyn.setTime(tt); }, tb);
          const c2 = await compareImages(browser, shots[0], Buffer.from(png).toString('base64'), traceColor);
          check(c2.traceB > 50 && c2.traceB > 3 * c2.traceA, 'the base\'s trace is drawn',
            `${c2.traceB} trace-coloured pixels with the robot hidden at the last time (${file}), ${c2.traceA} at the first time`);
        } else {
          console.log('  (no base trace on this page: the trace check is skipped)');
        }
      }
    }
    if (!a.missingMesh) await uiChecks(page, a, viewClip);
    check(consoleErrors.length === 0, 'no console error and no page error', consoleErrors.join(' | ').slice(0, 2000));
    check(requests.length === 0, 'the page fetched nothing', requests.slice(0, 5).join(', '));
  } finally {
    await browser.close();
  }
  console.log(`browser_test: ${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

// The controls a person uses: play/pause, the run list, overlay, follow base.
async function uiChecks(page, a, viewClip) {
  const st = () => page.evaluate(() => window.nhdyn.state());
  const n = await page.evaluate((k) => window.NHDYN_DATA.runs[k].t.length, a.run);
  if (n < 2) return;
  await page.evaluate((k) => { window.nhdyn.setRun(k); window.nhdyn.setTime(window.NHDYN_DATA.runs[k].t[0]); }, a.run);
  const before = await st();
  await page.click('#play');
  // Time moves in animation frames: on a loaded machine (a parallel ctest, software WebGL) the
  // first frame can take longer than a fixed wait, so poll until it moves (at most 10 s).
  const deadline = Date.now() + 10000;
  let during;
  do {
    await new Promise((r) => setTimeout(r, 200));
    during = await st();
  } while (during.playing && !(during.t > before.t) && Date.now() < deadline);
  await page.click('#play');
  const after = await st();
  check(during.playing && during.t > before.t && !after.playing, 'play advances the time, pause stops it',
    `t ${before.t} -> ${during.t.toFixed(3)} s while playing`);
  const nRuns = await page.evaluate(() => window.NHDYN_DATA.runs.length);
  if (nRuns > 1) {
    const other = a.run === 0 ? 1 : 0;
    await page.select('#run', String(other));
    const s1 = await st();
    await page.click('#overlay');
    const s2 = await st();
    const file = path.join(a.out, 'overlay.png');
    await page.screenshot({ path: file, clip: viewClip });
    await page.click('#overlay');
    await page.select('#run', String(a.run));
    check(s1.run === other && s2.overlay && (await st()).run === a.run, 'the run list selects a run; overlay all runs', file);
  }
  if (before.base) {
    const t = await page.evaluate((k) => window.NHDYN_DATA.runs[k].t, a.run);
    await page.evaluate((tt) => window.nhdyn.setTime(tt), t[0]);
    await page.click('#follow');
    const s0 = await st();
    await page.evaluate((tt) => window.nhdyn.setTime(tt), t[n - 1]);
    const s1 = await st();
    await page.click('#follow');
    const moved = [0, 1, 2].map((i) => s1.base[i] - s0.base[i]);
    const camMoved = [0, 1, 2].map((i) => s1.camera.target[i] - s0.camera.target[i]);
    const err = Math.max(...moved.map((v, i) => Math.abs(v - camMoved[i])));
    check(err < 1e-6, 'follow base: the camera moves with the base', `base moved ${Math.hypot(...moved).toFixed(3)} m`);
  }
}

// Pixel comparison in a blank tab (the page under test is not touched): how many pixels
// differ, and how many are of the trace's colour in each image.
async function compareImages(browser, a, b, traceHex) {
  const p = await browser.newPage();
  try {
    return await p.evaluate(async (a64, b64, hex) => {
      const load = (s) => new Promise((res, rej) => { const i = new Image(); i.onload = () => res(i); i.onerror = rej; i.src = 'data:image/png;base64,' + s; });
      const [ia, ib] = await Promise.all([load(a64), load(b64)]);
      const w = Math.min(ia.width, ib.width), h = Math.min(ia.height, ib.height);
      const px = (img) => { const c = document.createElement('canvas'); c.width = w; c.height = h; const g = c.getContext('2d'); g.drawImage(img, 0, 0); return g.getImageData(0, 0, w, h).data; };
      const da = px(ia), db = px(ib);
      const tc = [parseInt(hex.slice(1, 3), 16), parseInt(hex.slice(3, 5), 16), parseInt(hex.slice(5, 7), 16)];
      const isTrace = (d, i) => Math.abs(d[i] - tc[0]) + Math.abs(d[i + 1] - tc[1]) + Math.abs(d[i + 2] - tc[2]) < 60;
      let differ = 0, traceA = 0, traceB = 0;
      for (let i = 0; i < da.length; i += 4) {
        if (Math.max(Math.abs(da[i] - db[i]), Math.abs(da[i + 1] - db[i + 1]), Math.abs(da[i + 2] - db[i + 2])) > 24) differ++;
        if (isTrace(da, i)) traceA++;
        if (isTrace(db, i)) traceB++;
      }
      return { differ, total: w * h, traceA, traceB };
    }, a, b, traceHex);
  } finally {
    await p.close();
  }
}

main().catch((e) => { console.error('browser_test: ' + (e && e.stack || e)); console.log(`browser_test: ${passed} passed, ${failed + 1} failed`); process.exit(1); });
