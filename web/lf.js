/* lf.js - the living picture: refocus and move the viewpoint of a light
 * field in the browser (written by `lftool export-web`; docs/web.md).
 *
 * Data (data.js, window.LF_DATA): nu x nv sub-aperture views of ns x nt
 * pixels tiled into atlases (sRGB JPEG/PNG as data: URIs, view k = iv*nu + iu
 * at tile k % perAtlas of atlas floor(k / perAtlas), cols tiles a row), an
 * 8-bit disparity map over [min, max] and a focal stack for the fallback.
 * Focus is a disparity in lftool's convention; when the layout gives the
 * geometry, d = dispAtInf + dispPerInvM / Z names its distance Z in metres.
 *
 * Conventions are lftool's (docs/lftool.md): centred view coordinates
 * u = iu - (nu-1)/2, v = iv - (nv-1)/2; disparity d in pixels per view step,
 * a point of disparity d moves by -d pixels in s when the viewpoint moves one
 * view to +u (along v the disparity is d * dispVPerU).
 *
 * Rendering (WebGL 2): shift-and-add (Isaksen et al. 2000; Ng 2005) about
 * the viewpoint (u0, v0): out(s, t) = sum_k w_k L_k(s - d (u_k - u0),
 * t - d' (v_k - v0)) / sum_k w_k, the weights a disk of radius R around the
 * viewpoint (soft edge, so R changes continuously) or, when R is small, the
 * bilinear tent that interpolates between the four nearest views.  Views are
 * averaged in linear light (SRGB8_ALPHA8 textures) and encoded back to sRGB.
 * Without WebGL 2 the page shows the nearest focal-stack slice, or the
 * nearest view once the viewpoint moves.
 *
 * window.lfState reports what the page does (for tests and the curious):
 * path ("webgl2" | "stack"), focus, aperture, eyeU, eyeV, firstFrameMs
 * (performance.now() when the first frame was complete), frames.
 */
(function () {
  'use strict';
  var D = window.LF_DATA;
  var status = document.getElementById('status');
  if (!D || D.version !== 1) {
    status.textContent = 'data.js is missing or from another version of lftool';
    return;
  }
  var nviews = D.nu * D.nv;
  var cu = (D.nu - 1) / 2, cv = (D.nv - 1) / 2;
  var apertureMax = Math.hypot(cu, cv);
  var state = (window.lfState = {
    path: null,
    focus: 0.5 * (D.focusMin + D.focusMax),
    aperture: apertureMax,
    eyeU: 0,
    eyeV: 0,
    firstFrameMs: null,
    frames: 0,
    ready: false
  });
  var params = new URLSearchParams(window.location.search);

  function loadImage(src) {
    return new Promise(function (resolve, reject) {
      var img = new Image();
      img.onload = function () { resolve(img); };
      img.onerror = function () { reject(new Error('cannot decode an image in data.js')); };
      img.src = src;
    });
  }

  /* ---------- disparity map: click-to-focus ---------- */
  var disparity = null; /* Uint8Array, ns * nt */
  function readDisparity(img) {
    /* colorSpaceConversion none: the grey levels are codes, not colours */
    return createImageBitmap(img, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' }).then(function (bmp) {
      var c = document.createElement('canvas');
      c.width = D.ns;
      c.height = D.nt;
      var ctx = c.getContext('2d', { willReadFrequently: true });
      ctx.drawImage(bmp, 0, 0);
      var rgba = ctx.getImageData(0, 0, D.ns, D.nt).data;
      disparity = new Uint8Array(D.ns * D.nt);
      for (var i = 0; i < disparity.length; i++) disparity[i] = rgba[4 * i];
    });
  }
  /* Median disparity in a small window: robust to the odd wrong pixel of the
   * contrast-based estimate near edges. */
  function disparityAt(s, t) {
    var r = 3, vals = [];
    for (var y = Math.max(0, t - r); y <= Math.min(D.nt - 1, t + r); y++)
      for (var x = Math.max(0, s - r); x <= Math.min(D.ns - 1, s + r); x++) vals.push(disparity[y * D.ns + x]);
    vals.sort(function (a, b) { return a - b; });
    var g = vals[vals.length >> 1];
    return D.disparity.min + (D.disparity.max - D.disparity.min) * g / 255;
  }

  /* ---------- WebGL 2 shift-and-add ---------- */
  var VS = '#version 300 es\n' +
    'uniform vec2 tile;\n' +
    'out vec2 st;\n' +
    'void main() {\n' +
    '  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));\n' +
    '  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n' +
    '  st = vec2(p.x, 1.0 - p.y) * tile;\n' + /* pixel units, row 0 at the top */
    '}\n';
  var FS = '#version 300 es\n' +
    'precision highp float;\n' +
    'precision highp sampler2DArray;\n' +
    'uniform sampler2DArray views;\n' +
    'uniform ivec3 layout_;\n' +   /* nu, atlas columns, views per atlas */
    'uniform int nviews;\n' +
    'uniform vec2 tile, atlas, centre, eye;\n' +
    'uniform float disp, dispV, radius;\n' +
    'in vec2 st;\n' +
    'out vec4 color;\n' +
    'vec3 srgb(vec3 c) { return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c)); }\n' +
    'void main() {\n' +
    '  vec3 acc = vec3(0.0);\n' +
    '  float wsum = 0.0;\n' +
    '  for (int k = 0; k < nviews; k++) {\n' +
    '    vec2 du = vec2(float(k % layout_.x), float(k / layout_.x)) - centre - eye;\n' +
    '    vec2 tent = max(vec2(0.0), 1.0 - abs(du));\n' +
    '    float w = max(clamp(radius + 0.5 - length(du), 0.0, 1.0), tent.x * tent.y);\n' +
    '    if (w <= 0.0) continue;\n' +
    '    vec2 p = clamp(st - disp * vec2(du.x, dispV * du.y), vec2(0.5), tile - 0.5);\n' +
    '    int j = k % layout_.z;\n' +
    '    vec2 origin = vec2(float(j % layout_.y), float(j / layout_.y)) * tile;\n' +
    '    acc += w * texture(views, vec3((origin + p) / atlas, float(k / layout_.z))).rgb;\n' +
    '    wsum += w;\n' +
    '  }\n' +
    '  color = vec4(srgb(acc / max(wsum, 1e-6)), 1.0);\n' +
    '}\n';

  function compile(gl, type, src) {
    var sh = gl.createShader(type);
    gl.shaderSource(sh, src);
    gl.compileShader(sh);
    if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(sh));
    return sh;
  }

  function makeWebGL(canvas, atlases) {
    var gl = canvas.getContext('webgl2', { antialias: false, depth: false, alpha: false });
    if (!gl) return null;
    var w = 0, h = 0;
    atlases.forEach(function (a) { w = Math.max(w, a.width); h = Math.max(h, a.height); });
    if (w > gl.getParameter(gl.MAX_TEXTURE_SIZE) || h > gl.getParameter(gl.MAX_TEXTURE_SIZE)) return null;
    var prog = gl.createProgram();
    gl.attachShader(prog, compile(gl, gl.VERTEX_SHADER, VS));
    gl.attachShader(prog, compile(gl, gl.FRAGMENT_SHADER, FS));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error('link: ' + gl.getProgramInfoLog(prog));
    var tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex);
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
    gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, gl.SRGB8_ALPHA8, w, h, atlases.length);
    atlases.forEach(function (a, i) {
      gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, i, a.width, a.height, 1, gl.RGBA, gl.UNSIGNED_BYTE, a);
    });
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    gl.useProgram(prog);
    var u = {};
    ['views', 'layout_', 'nviews', 'tile', 'atlas', 'centre', 'eye', 'disp', 'dispV', 'radius'].forEach(function (n) {
      u[n] = gl.getUniformLocation(prog, n);
    });
    gl.uniform1i(u.views, 0);
    gl.uniform3i(u.layout_, D.nu, D.views.cols, D.views.perAtlas);
    gl.uniform1i(u.nviews, nviews);
    gl.uniform2f(u.tile, D.ns, D.nt);
    gl.uniform2f(u.atlas, w, h);
    gl.uniform2f(u.centre, cu, cv);
    gl.uniform1f(u.dispV, D.dispVPerU);
    gl.viewport(0, 0, D.ns, D.nt);
    var err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error('WebGL setup failed: error 0x' + err.toString(16));
    return {
      gl: gl,
      draw: function () {
        gl.uniform2f(u.eye, state.eyeU, state.eyeV);
        gl.uniform1f(u.disp, state.focus);
        gl.uniform1f(u.radius, state.aperture);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      },
      sync: function () {
        var px = new Uint8Array(4);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
      }
    };
  }

  /* ---------- fallback: focal stack and single views on a 2D canvas ---------- */
  function makeStack(canvas, atlases, stackImg) {
    var ctx = canvas.getContext('2d');
    var S = D.stack, n = S.disparities.length;
    return {
      draw: function () {
        var moved = Math.abs(state.eyeU) > 0.25 || Math.abs(state.eyeV) > 0.25;
        if (moved || state.aperture < 0.5) {
          /* a pinhole view: the captured view nearest the viewpoint */
          var iu = Math.round(state.eyeU + cu), iv = Math.round(state.eyeV + cv);
          var k = iv * D.nu + iu, j = k % D.views.perAtlas;
          ctx.drawImage(atlases[Math.floor(k / D.views.perAtlas)], (j % D.views.cols) * D.ns,
            Math.floor(j / D.views.cols) * D.nt, D.ns, D.nt, 0, 0, D.ns, D.nt);
        } else {
          var best = 0;
          for (var i = 1; i < n; i++)
            if (Math.abs(S.disparities[i] - state.focus) < Math.abs(S.disparities[best] - state.focus)) best = i;
          ctx.drawImage(stackImg, (best % S.cols) * D.ns, Math.floor(best / S.cols) * D.nt, D.ns, D.nt, 0, 0, D.ns, D.nt);
        }
      },
      sync: function () { ctx.getImageData(0, 0, 1, 1); }
    };
  }

  /* ---------- UI ---------- */
  var canvas = document.getElementById('lf'), frameEl = document.getElementById('frame');
  var focusIn = document.getElementById('focus'), apertureIn = document.getElementById('aperture');
  var renderer = null, pending = false;

  function fmt(x) { return (Math.round(x * 100) / 100).toFixed(2); }
  function showState() {
    focusIn.value = state.focus;
    apertureIn.value = state.aperture;
    /* d = dispAtInf + dispPerInvM / Z (docs/lftool.md): the focus distance when the layout gives it */
    var z = D.dispPerInvM > 0 && state.focus > D.dispAtInf ? D.dispPerInvM / (state.focus - D.dispAtInf) : 0;
    document.getElementById('focus-val').textContent = fmt(state.focus) + ' px' + (z ? ' \u00b7 ' + fmt(z) + ' m' : '');
    document.getElementById('aperture-val').textContent = fmt(state.aperture);
    status.textContent = (state.path === 'webgl2' ? 'WebGL 2 shift-and-add' : 'focal stack (no WebGL 2)') +
      ' \u00b7 ' + D.nu + '\u00d7' + D.nv + ' views of ' + D.ns + '\u00d7' + D.nt +
      ' \u00b7 viewpoint (' + fmt(state.eyeU) + ', ' + fmt(state.eyeV) + ')' +
      (state.firstFrameMs !== null ? ' \u00b7 first frame ' + Math.round(state.firstFrameMs) + ' ms' : '');
  }
  function frame() {
    pending = false;
    renderer.draw();
    state.frames++;
    if (state.firstFrameMs === null) {
      renderer.sync();
      state.firstFrameMs = performance.now();
      state.ready = true;
    }
    showState();
  }
  function redraw() {
    if (renderer && !pending) {
      pending = true;
      requestAnimationFrame(frame);
    }
  }
  function setFocus(d) {
    var lo = Number(focusIn.min), hi = Number(focusIn.max);
    state.focus = Math.min(hi, Math.max(lo, d));
    redraw();
  }

  /* Pointer: a press that moves less than 4 px is a click (focus there);
   * otherwise a drag moves the viewpoint.  Dragging across the whole picture
   * sweeps the whole captured aperture; the scene turns with the pointer
   * (near objects follow it), so the viewpoint moves the other way. */
  var press = null;
  function toPixel(e) {
    var r = canvas.getBoundingClientRect();
    return {
      s: Math.min(D.ns - 1, Math.max(0, Math.floor((e.clientX - r.left) / r.width * D.ns))),
      t: Math.min(D.nt - 1, Math.max(0, Math.floor((e.clientY - r.top) / r.height * D.nt)))
    };
  }
  frameEl.addEventListener('pointerdown', function (e) {
    press = { x: e.clientX, y: e.clientY, u: state.eyeU, v: state.eyeV, dragging: false };
    frameEl.setPointerCapture(e.pointerId);
  });
  frameEl.addEventListener('pointermove', function (e) {
    if (!press) return;
    var dx = e.clientX - press.x, dy = e.clientY - press.y;
    if (!press.dragging && Math.hypot(dx, dy) < 4) return;
    press.dragging = true;
    canvas.classList.add('dragging');
    var r = canvas.getBoundingClientRect();
    state.eyeU = Math.min(cu, Math.max(-cu, press.u - dx / r.width * 2 * cu));
    state.eyeV = Math.min(cv, Math.max(-cv, press.v - dy / r.height * 2 * cv));
    redraw();
  });
  function release(e, click) {
    if (!press) return;
    if (click && !press.dragging && disparity) {
      var p = toPixel(e);
      setFocus(disparityAt(p.s, p.t));
    }
    press = null;
    canvas.classList.remove('dragging');
  }
  frameEl.addEventListener('pointerup', function (e) { release(e, true); });
  frameEl.addEventListener('pointercancel', function (e) { release(e, false); });
  frameEl.addEventListener('wheel', function (e) {
    e.preventDefault();
    var step = (Number(focusIn.max) - Number(focusIn.min)) / 50;
    setFocus(state.focus - Math.sign(e.deltaY) * step);
  }, { passive: false });
  focusIn.addEventListener('input', function () { setFocus(Number(focusIn.value)); });
  apertureIn.addEventListener('input', function () { state.aperture = Number(apertureIn.value); redraw(); });
  document.getElementById('reset').addEventListener('click', function () {
    state.eyeU = state.eyeV = 0;
    redraw();
  });

  /* Integer display scale up to ~640 px, so the picture stays pixel-exact. */
  function layoutCanvas() {
    var room = Math.min(window.innerWidth - 24, 640), roomH = Math.max(window.innerHeight - 170, 96);
    var k = Math.max(1, Math.floor(Math.min(room / D.ns, roomH / D.nt)));
    if (D.ns > room) k = room / D.ns;
    canvas.style.width = D.ns * k + 'px';
    canvas.style.height = D.nt * k + 'px';
  }

  /* Frames per second of the renderer, drawn back to back (tests, docs/web.md). */
  window.lfBench = function (frames) {
    var saved = state.focus, t0 = performance.now();
    for (var i = 0; i < frames; i++) {
      state.focus = D.focusMin + (D.focusMax - D.focusMin) * (i % 7) / 6;
      renderer.draw();
      renderer.sync();
    }
    var ms = (performance.now() - t0) / frames;
    state.focus = saved;
    redraw();
    return { msPerFrame: ms, path: state.path };
  };

  var pad = 0.1 * (D.focusMax - D.focusMin);
  focusIn.min = D.focusMin - pad;
  focusIn.max = D.focusMax + pad;
  apertureIn.min = 0;
  apertureIn.max = apertureMax;
  canvas.width = D.ns;
  canvas.height = D.nt;
  layoutCanvas();
  window.addEventListener('resize', layoutCanvas);

  Promise.all([Promise.all(D.views.atlases.map(loadImage)), loadImage(D.disparity.src), loadImage(D.stack.src)])
    .then(function (img) {
      var atlases = img[0];
      return readDisparity(img[1]).then(function () {
        /* the median disparity of the picture: what most of it shows */
        var sorted = Array.from(disparity).sort(function (a, b) { return a - b; });
        state.focus = D.disparity.min + (D.disparity.max - D.disparity.min) * sorted[sorted.length >> 1] / 255;
        if (params.get('renderer') !== 'stack') renderer = makeWebGL(canvas, atlases);
        if (renderer) {
          state.path = 'webgl2';
        } else {
          /* a canvas that tried WebGL cannot give a 2D context: use a fresh one */
          var fresh = canvas.cloneNode(false);
          canvas.parentNode.replaceChild(fresh, canvas);
          canvas = fresh;
          state.path = 'stack';
          renderer = makeStack(canvas, atlases, img[2]);
        }
        redraw();
      });
    })
    .catch(function (e) {
      status.textContent = 'cannot show the light field: ' + e.message;
      throw e;
    });
})();
