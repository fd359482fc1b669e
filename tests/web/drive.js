#!/usr/bin/env node
/* drive.js - drives headless Chromium through an exported light-field page
 * (tests/test_web_export.sh; docs/web.md) with real input events over the
 * Chrome DevTools Protocol on --remote-debugging-pipe.  No npm packages:
 * Node's standard library only (child_process, zlib).
 *
 *   node drive.js CONFIG.json
 *
 * CONFIG: {chromium, flags: [...], userDataDir, runs: [{name, url, path, checks, bench, extraFlags}],
 *          near: {s, t, d}, far: {s, t, d}, radius}
 * near/far: a pixel (view coordinates) on each object and its true disparity.
 * A run with checks "full" clicks far, near, far and measures local contrast
 * (variance of the Laplacian of luminance) around each clicked pixel before
 * and after, then drags the viewpoint and measures the image shift of the
 * near object relative to the far one; "load" only loads the page.  Every
 * run asserts no console errors, page errors or failed loads, and that no
 * request leaves file:, data: or the given http origin.
 * Prints one line per check and "browser: N passed, N failed"; exits 1 on failure.
 */
'use strict';
const { spawn } = require('child_process');
const fs = require('fs');
const zlib = require('zlib');

const cfg = JSON.parse(fs.readFileSync(process.argv[2], 'utf8'));
let passed = 0, failed = 0;
function check(ok, what) {
  if (ok) passed++;
  else failed++;
  console.log((ok ? 'ok   ' : 'FAIL ') + what);
}

/* ---------- CDP over a pipe: fd 3 to Chromium, fd 4 from it, NUL-separated JSON ---------- */
function launch(extraFlags, profile) {
  const args = cfg.flags.concat(extraFlags || [], ['--remote-debugging-pipe', '--user-data-dir=' + profile, 'about:blank']);
  const proc = spawn(cfg.chromium, args, { stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe'] });
  let stderr = '';
  proc.stderr.on('data', (b) => { stderr += b; });
  const out = proc.stdio[3], inp = proc.stdio[4];
  let nextId = 1, buf = '';
  const waiting = new Map(), listeners = [];
  inp.on('data', (chunk) => {
    buf += chunk.toString('utf8');
    let z;
    while ((z = buf.indexOf('\0')) >= 0) {
      const msg = JSON.parse(buf.slice(0, z));
      buf = buf.slice(z + 1);
      if (msg.id && waiting.has(msg.id)) {
        const w = waiting.get(msg.id);
        waiting.delete(msg.id);
        if (msg.error) w.reject(new Error(w.method + ': ' + msg.error.message));
        else w.resolve(msg.result);
      } else if (msg.method) {
        listeners.forEach((l) => l(msg));
      }
    }
  });
  const exited = new Promise((resolve) => proc.on('exit', (code, sig) => resolve({ code, sig })));
  exited.then(() => waiting.forEach((w) => w.reject(new Error('chromium exited: ' + stderr.slice(-2000)))));
  return {
    proc,
    exited,
    send(method, params, sessionId) {
      const id = nextId++;
      const msg = { id, method, params: params || {} };
      if (sessionId) msg.sessionId = sessionId;
      out.write(JSON.stringify(msg) + '\0');
      return new Promise((resolve, reject) => waiting.set(id, { resolve, reject, method }));
    },
    on(fn) { listeners.push(fn); },
    stderr: () => stderr
  };
}

/* ---------- PNG decoding (8-bit RGB/RGBA, non-interlaced: what Chromium writes) ---------- */
function decodePng(buf) {
  let pos = 8, w = 0, h = 0, ctype = 0;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos), type = buf.toString('ascii', pos + 4, pos + 8);
    const data = buf.subarray(pos + 8, pos + 8 + len);
    if (type === 'IHDR') {
      w = data.readUInt32BE(0), h = data.readUInt32BE(4), ctype = data[9];
      if (data[8] !== 8 || data[12] !== 0 || (ctype !== 2 && ctype !== 6)) throw new Error('unsupported PNG');
    } else if (type === 'IDAT') idat.push(data);
    pos += 12 + len;
  }
  const bpp = ctype === 6 ? 4 : 3, stride = w * bpp;
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const px = Buffer.alloc(h * stride);
  for (let y = 0; y < h; y++) {
    const f = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= bpp ? px[y * stride + x - bpp] : 0, b = y ? px[(y - 1) * stride + x] : 0;
      const c = x >= bpp && y ? px[(y - 1) * stride + x - bpp] : 0;
      let p;
      if (f === 0) p = 0;
      else if (f === 1) p = a;
      else if (f === 2) p = b;
      else if (f === 3) p = (a + b) >> 1;
      else {
        const q = a + b - c, pa = Math.abs(q - a), pb = Math.abs(q - b), pc = Math.abs(q - c);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      px[y * stride + x] = (line[x] + p) & 255;
    }
  }
  return { w, h, bpp, px };
}

/* Screenshot pixels -> luminance on the view's (s, t) grid: the page scales
 * the canvas by an integer factor with pixelated rendering, so a box average
 * over each k x k block gives the canvas pixel back. */
function toGrid(png, ns, nt) {
  const kx = png.w / ns, ky = png.h / nt, g = new Float64Array(ns * nt);
  for (let t = 0; t < nt; t++)
    for (let s = 0; s < ns; s++) {
      let acc = 0, n = 0;
      for (let y = Math.floor(t * ky); y < Math.floor((t + 1) * ky); y++)
        for (let x = Math.floor(s * kx); x < Math.floor((s + 1) * kx); x++) {
          const i = (y * png.w + x) * png.bpp;
          acc += 0.2126 * png.px[i] + 0.7152 * png.px[i + 1] + 0.0722 * png.px[i + 2];
          n++;
        }
      g[t * ns + s] = acc / n / 255;
    }
  return g;
}

/* Local contrast: variance of the 4-neighbour Laplacian in a (2r+1)^2 window. */
function contrast(g, ns, nt, cs, ct, r) {
  const v = [];
  for (let t = Math.max(1, ct - r); t <= Math.min(nt - 2, ct + r); t++)
    for (let s = Math.max(1, cs - r); s <= Math.min(ns - 2, cs + r); s++)
      v.push(4 * g[t * ns + s] - g[t * ns + s - 1] - g[t * ns + s + 1] - g[(t - 1) * ns + s] - g[(t + 1) * ns + s]);
  const m = v.reduce((a, b) => a + b, 0) / v.length;
  return v.reduce((a, b) => a + (b - m) * (b - m), 0) / v.length;
}

/* Shift (dx, dy) of the window around (cs, ct) from image a to image b:
 * integer search minimising the mean squared difference, refined by a
 * parabola through the neighbours on each axis. */
function shift(a, b, ns, nt, cs, ct, r, range) {
  const ssd = (dx, dy) => {
    let acc = 0, n = 0;
    for (let t = ct - r; t <= ct + r; t++)
      for (let s = cs - r; s <= cs + r; s++) {
        const s2 = s + dx, t2 = t + dy;
        if (s < 0 || t < 0 || s >= ns || t >= nt || s2 < 0 || t2 < 0 || s2 >= ns || t2 >= nt) continue;
        const d = a[t * ns + s] - b[t2 * ns + s2];
        acc += d * d, n++;
      }
    return acc / n;
  };
  let best = [0, 0], bestv = Infinity;
  for (let dy = -range; dy <= range; dy++)
    for (let dx = -range; dx <= range; dx++) {
      const v = ssd(dx, dy);
      if (v < bestv) bestv = v, best = [dx, dy];
    }
  const refine = (m, c, p) => (m + p - 2 * c > 0 ? (0.5 * (m - p)) / (m + p - 2 * c) : 0);
  const [bx, by] = best;
  return [bx + refine(ssd(bx - 1, by), bestv, ssd(bx + 1, by)), by + refine(ssd(bx, by - 1), bestv, ssd(bx, by + 1))];
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function run(cdp, spec) {
  const { targetId } = await cdp.send('Target.createTarget', { url: 'about:blank' });
  const { sessionId } = await cdp.send('Target.attachToTarget', { targetId, flatten: true });
  const S = (m, p) => cdp.send(m, p, sessionId);
  const errors = [], requests = [];
  cdp.on((msg) => {
    if (msg.sessionId !== sessionId) return;
    const p = msg.params;
    if (msg.method === 'Runtime.exceptionThrown') errors.push('exception: ' + JSON.stringify(p.exceptionDetails).slice(0, 500));
    else if (msg.method === 'Runtime.consoleAPICalled' && (p.type === 'error' || p.type === 'assert'))
      errors.push('console.' + p.type + ': ' + p.args.map((a) => a.value || a.description).join(' '));
    else if (msg.method === 'Log.entryAdded' && p.entry.level === 'error') errors.push('log: ' + p.entry.text + ' ' + (p.entry.url || ''));
    else if (msg.method === 'Network.requestWillBeSent') requests.push(p.request.url);
    else if (msg.method === 'Network.loadingFailed') errors.push('load failed: ' + p.errorText);
  });
  await S('Runtime.enable');
  await S('Log.enable');
  await S('Page.enable');
  await S('Network.enable');
  await S('Emulation.setDeviceMetricsOverride', { width: 1000, height: 800, deviceScaleFactor: 1, mobile: false });
  const evaluate = async (expr) => {
    const r = await S('Runtime.evaluate', { expression: expr, returnByValue: true, awaitPromise: true });
    if (r.exceptionDetails) throw new Error('evaluate ' + expr + ': ' + JSON.stringify(r.exceptionDetails).slice(0, 300));
    return r.result.value;
  };
  const t0 = Date.now();
  await S('Page.navigate', { url: spec.url });
  let ready = false;
  for (let i = 0; i < 600 && !ready; i++) {
    await sleep(50);
    ready = await evaluate('!!(window.lfState && window.lfState.ready)').catch(() => false);
  }
  const wall = Date.now() - t0;
  check(ready, spec.name + ': page shows its first frame');
  if (!ready) return;
  const st = () => evaluate('JSON.parse(JSON.stringify(window.lfState))');
  let state = await st();
  console.log(`     ${spec.name}: rendering path ${state.path}; first frame at ${state.firstFrameMs.toFixed(0)} ms after ` +
    `navigation start (${wall} ms wall clock from the navigate command)`);
  /* "webgl2|stack": WebGL 2 expected, but a browser without it must still
   * pass every check on the fallback (and says so) */
  check(spec.path.split('|').includes(state.path), `${spec.name}: rendering path is ${spec.path} (got ${state.path})`);
  if (state.path !== spec.path.split('|')[0])
    console.log(`     NOTE ${spec.name}: WebGL 2 is unavailable in this browser; the checks below ran on the focal-stack fallback`);
  const D = await evaluate('({ns: LF_DATA.ns, nt: LF_DATA.nt, nu: LF_DATA.nu, nv: LF_DATA.nv})');

  if (spec.checks === 'full') {
    /* settle: a promise that resolves after two animation frames */
    const settle = () => evaluate('new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r(1))))');
    const rect = await evaluate('(() => { const r = document.getElementById("lf").getBoundingClientRect(); ' +
      'return {x: r.left, y: r.top, w: r.width, h: r.height}; })()');
    const at = (p) => ({ x: rect.x + (p.s + 0.5) * rect.w / D.ns, y: rect.y + (p.t + 0.5) * rect.h / D.nt });
    const mouse = (type, x, y, buttons) => S('Input.dispatchMouseEvent',
      { type, x, y, button: type === 'mouseMoved' && !buttons ? 'none' : 'left', buttons: buttons || 0, clickCount: 1 });
    const click = async (p) => {
      const q = at(p);
      await mouse('mouseMoved', q.x, q.y, 0);
      await mouse('mousePressed', q.x, q.y, 1);
      await mouse('mouseReleased', q.x, q.y, 0);
      await settle();
    };
    const shot = async () => {
      await settle();
      const r = await S('Page.captureScreenshot', { format: 'png', clip: { x: rect.x, y: rect.y, width: rect.w, height: rect.h, scale: 1 } });
      return toGrid(decodePng(Buffer.from(r.data, 'base64')), D.ns, D.nt);
    };
    const R = cfg.radius, near = cfg.near, far = cfg.far;
    const C = (g, p) => contrast(g, D.ns, D.nt, p.s, p.t, R);
    const fmt = (x) => x.toFixed(5);

    const s0 = await shot();
    await click(far);
    const dFar = (await st()).focus, s1 = await shot();
    await click(near);
    const dNear = (await st()).focus, s2 = await shot();
    await click(far);
    const dFar2 = (await st()).focus, s3 = await shot();
    console.log(`     ${spec.name}: clicked far -> focus ${dFar.toFixed(3)} px/view (true ${far.d.toFixed(3)}), ` +
      `near -> ${dNear.toFixed(3)} (true ${near.d.toFixed(3)}), far again -> ${dFar2.toFixed(3)}`);
    const tol = state.path === 'stack' ? 0.45 : 0.35;
    check(Math.abs(dNear - near.d) < tol, `${spec.name}: click on the near object focuses at its disparity (|${dNear.toFixed(3)} - ${near.d.toFixed(3)}| < ${tol})`);
    check(Math.abs(dFar - far.d) < tol, `${spec.name}: click on the far object focuses at its disparity (|${dFar.toFixed(3)} - ${far.d.toFixed(3)}| < ${tol})`);
    const cn1 = C(s1, near), cn2 = C(s2, near), cf2 = C(s2, far), cf3 = C(s3, far);
    console.log(`     ${spec.name}: local contrast (variance of the Laplacian, ${2 * R + 1}x${2 * R + 1} px) at the near object: ` +
      `${fmt(C(s0, near))} initially, ${fmt(cn1)} focused far, ${fmt(cn2)} after clicking it (x${(cn2 / cn1).toFixed(2)})`);
    console.log(`     ${spec.name}: at the far object: ${fmt(C(s0, far))} initially, ${fmt(cf2)} focused near, ` +
      `${fmt(cf3)} after clicking it (x${(cf3 / cf2).toFixed(2)})`);
    check(cn2 > 1.5 * cn1, `${spec.name}: clicking the near object makes it sharper (contrast x${(cn2 / cn1).toFixed(2)} > 1.5)`);
    check(cf3 > 1.5 * cf2, `${spec.name}: clicking the far object makes it sharper (contrast x${(cf3 / cf2).toFixed(2)} > 1.5)`);

    /* wheel: scrolling up focuses nearer (larger disparity) */
    const q = at(far);
    await S('Input.dispatchMouseEvent', { type: 'mouseWheel', x: q.x, y: q.y, deltaX: 0, deltaY: -100 });
    await settle();
    const dWheel = (await st()).focus;
    check(dWheel > dFar2, `${spec.name}: scrolling up moves the focus nearer (${dFar2.toFixed(3)} -> ${dWheel.toFixed(3)})`);

    /* parallax: pinhole aperture (the slider to its minimum with the Home
     * key), then drag a quarter of the picture right and down */
    await evaluate('document.getElementById("aperture").focus(), 1');
    await S('Input.dispatchKeyEvent', { type: 'rawKeyDown', key: 'Home', code: 'Home', windowsVirtualKeyCode: 36 });
    await S('Input.dispatchKeyEvent', { type: 'keyUp', key: 'Home', code: 'Home', windowsVirtualKeyCode: 36 });
    await settle();
    const before = await st(), a = await shot();
    check(before.aperture === 0, `${spec.name}: Home on the aperture slider gives a pinhole (aperture ${before.aperture})`);
    const c = at({ s: D.ns / 2, t: D.nt / 2 }), dx = rect.w / 4, dy = rect.h / 4;
    await mouse('mouseMoved', c.x, c.y, 0);
    await mouse('mousePressed', c.x, c.y, 1);
    for (let i = 1; i <= 8; i++) await mouse('mouseMoved', c.x + dx * i / 8, c.y + dy * i / 8, 1);
    await mouse('mouseReleased', c.x + dx, c.y + dy, 0);
    const after = await st(), b = await shot();
    const du = after.eyeU - before.eyeU, dv = after.eyeV - before.eyeV;
    const range = Math.ceil(Math.max(Math.abs(du), Math.abs(dv)) * Math.max(near.d, far.d)) + 3;
    const sn = shift(a, b, D.ns, D.nt, near.s, near.t, R, range), sf = shift(a, b, D.ns, D.nt, far.s, far.t, R, range);
    /* a point of disparity d moves by -d * (viewpoint change) */
    const want = [-(near.d - far.d) * du, -(near.d - far.d) * dv * (cfg.dispVPerU || 1)];
    const rel = [sn[0] - sf[0], sn[1] - sf[1]];
    console.log(`     ${spec.name}: drag (${dx.toFixed(0)}, ${dy.toFixed(0)}) px moved the viewpoint by (${du.toFixed(2)}, ${dv.toFixed(2)}) views; ` +
      `near object shifted (${sn[0].toFixed(2)}, ${sn[1].toFixed(2)}) px, far (${sf[0].toFixed(2)}, ${sf[1].toFixed(2)}); ` +
      `relative (${rel[0].toFixed(2)}, ${rel[1].toFixed(2)}), expected (${want[0].toFixed(2)}, ${want[1].toFixed(2)})`);
    check(Math.abs(du) > 0.5 && Math.abs(dv) > 0.5, `${spec.name}: dragging moves the viewpoint`);
    check(Math.hypot(rel[0], rel[1]) > 1, `${spec.name}: dragging changes parallax (near object moves ${Math.hypot(rel[0], rel[1]).toFixed(2)} px relative to the far one)`);
    check(Math.abs(rel[0] - want[0]) < 0.6 && Math.abs(rel[1] - want[1]) < 0.6,
      `${spec.name}: relative shift matches the disparities within 0.6 px`);
  }
  if (spec.bench) {
    await evaluate('document.getElementById("aperture").value = 1e9, document.getElementById("aperture").dispatchEvent(new Event("input")), 1');
    const bench = await evaluate(`window.lfBench(${spec.bench})`);
    console.log(`     ${spec.name}: ${bench.msPerFrame.toFixed(1)} ms per frame (${(1000 / bench.msPerFrame).toFixed(1)} frames/s, ` +
      `${D.nu}x${D.nv} views of ${D.ns}x${D.nt}, full aperture, ${spec.bench} frames drawn back to back, path ${bench.path})`);
  }
  await sleep(100);
  const foreign = requests.filter((u) => !(u.startsWith('file:') || u.startsWith('data:') ||
    (spec.origin && u.startsWith(spec.origin))));
  check(foreign.length === 0, `${spec.name}: no request leaves the page's folder (${requests.length} requests${foreign.length ? '; foreign: ' + foreign.join(' ') : ''})`);
  check(errors.length === 0, `${spec.name}: no console errors, page errors or failed loads${errors.length ? ': ' + errors.join(' | ') : ''}`);
  await cdp.send('Target.closeTarget', { targetId });
}

/* One fresh browser (and profile) per run: a run may add flags
 * (extraFlags, e.g. --disable-3d-apis for the automatic fallback). */
async function runInBrowser(spec) {
  const cdp = launch(spec.extraFlags, cfg.userDataDir + '/' + spec.name);
  const timer = setTimeout(() => {
    console.log('FAIL timed out; chromium stderr:\n' + cdp.stderr().slice(-3000));
    cdp.proc.kill('SIGKILL');
    process.exit(1);
  }, (cfg.timeoutSeconds || 300) * 1000);
  try {
    const v = await cdp.send('Browser.getVersion');
    console.log(`     ${spec.name}: ${v.product} (${v.userAgent.includes('Headless') ? 'headless' : 'headed'})` +
      (spec.extraFlags ? ' with ' + spec.extraFlags.join(' ') : ''));
    await run(cdp, spec);
  } catch (e) {
    check(false, spec.name + ': driver: ' + e.message);
  }
  clearTimeout(timer);
  await cdp.send('Browser.close').catch(() => {});
  await Promise.race([cdp.exited, sleep(5000)]);
  if (cdp.proc.exitCode === null && cdp.proc.signalCode === null) cdp.proc.kill('SIGKILL');
}

(async () => {
  for (const spec of cfg.runs) await runInBrowser(spec);
  console.log(`browser: ${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
})();
