// The explorer's appearance panel: the sample's colour (CIE 45°:0°) and a sphere of it lit by a
// distant light, in sRGB under CIE D65 and illuminant A, rendered by brdfd from the session's BRDF
// (Interpolation/RenderAppearance: the chosen method, filled where it has no value by Delaunay,
// then the fitted model). The spheres arrive as RGBA bytes (base64 in JSON) and are drawn to
// <canvas> through ImageData; the swatches are canvases too (no inline style: the CSP is strict).
import { call } from './api.js';
import { el, clear } from './dom.js';

function bytesOf(base64) {
  const bin = atob(base64);
  const out = new Uint8ClampedArray(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

function drawSphere(canvas, image) {
  const n = image.sphere_size;
  canvas.width = n;
  canvas.height = n;
  const ctx = canvas.getContext('2d');
  ctx.putImageData(new ImageData(bytesOf(image.sphere_rgba), n, n), 0, 0);
}

function drawSwatch(canvas, hex) {
  const ctx = canvas.getContext('2d');
  ctx.fillStyle = hex;
  ctx.fillRect(0, 0, canvas.width, canvas.height);
}

// Above this many sample readings the panel renders only when asked (see load()).
const AUTO_RENDER_READINGS = 20000;

export function createAppearance(root, report) {
  const method = el('select', { id: 'appearance-method' },
    el('option', { value: 'INTERPOLATION_METHOD_OCTANT' }, 'octant (paper)'),
    el('option', { value: 'INTERPOLATION_METHOD_DELAUNAY' }, 'Delaunay'),
    el('option', { value: 'INTERPOLATION_METHOD_NEAREST' }, 'nearest'));
  const info = el('p', { id: 'appearance-info', class: 'muted' }, 'Load a session.');
  const images = el('div', { id: 'appearance-images', class: 'row appearance' });
  let session = '';

  root.append(
    el('section', { id: 'appearance' },
      el('h2', {}, 'Colour and lit sphere'),
      el('div', { class: 'buttons' }, el('label', {}, 'method ', method),
        el('button', { id: 'appearance-render', onclick: () => render() }, 'Render')),
      info, images));

  function figure(image) {
    const name = image.name;
    const sphere = el('canvas', { id: `appearance-sphere-${name}`, class: 'appearance-sphere' });
    const swatch = el('canvas', { id: `appearance-swatch-${name}`, class: 'appearance-swatch', width: 48, height: 48 });
    drawSphere(sphere, image);
    drawSwatch(swatch, image.colour.srgb_hex);
    const c = image.colour;
    const lit = image.disc_pixels - image.unlit_pixels;
    return el('figure', { class: 'appearance-figure' }, sphere,
      el('figcaption', {},
        el('div', { class: 'buttons' }, swatch,
          el('span', { id: `appearance-colour-${name}` },
            `${name === 'A' ? 'illuminant A' : 'D65'}: ${c.srgb_hex}, x ${c.x.toFixed(4)}, y ${c.y.toFixed(4)}, Y ${c.y_tristimulus.toFixed(3)}`)),
        el('div', { class: 'muted' },
          `${lit} lit pixels: ${image.interpolated_pixels} interpolated, ${image.fallback_pixels} Delaunay, ${image.model_pixels} model` +
          (image.peak_y > 1 ? `; highlight clipped (peak Y ${image.peak_y.toFixed(2)})` : ''))));
  }

  async function render() {
    if (!session) { report('load a session first'); return; }
    info.textContent = 'rendering…';
    const t0 = performance.now();
    try {
      // Mirror images and reciprocity: exact for an isotropic sample, and what the RGL and MERL
      // exports use, so the chosen method answers more of the sphere itself.
      // Up to 10 minutes: the first render of a large session builds its indexes (the answer is
      // then kept by the daemon, and the same render again is immediate).
      const r = await call('Interpolation/RenderAppearance', { session_id: session, method: method.value, options: { mirror_phi: true, reciprocity: true } }, 600);
      clear(images);
      for (const image of r.images) images.append(figure(image));
      info.textContent = `sample colour at 45°:0° (reflectance factor π·f_r) and a sphere lit from the upper left, sRGB, readings mirrored in φ and swapped θi↔θo; a white Lambertian lit head-on would be Y = 1 (${Math.round(performance.now() - t0)} ms)${r.detail ? `. ${r.detail}` : ''}`;
    } catch (e) {
      clear(images);
      info.textContent = e.message;
    }
  }

  return {
    // A session of `readings` sample readings was loaded in the explorer: rendered at once, but
    // for a large session only on request. Its first render builds the fill chain's indexes over
    // every reading (mirrored and swapped: 4×), which on 50,000 readings takes the daemon several
    // seconds (tens on a busy machine) and its one work permit; the plots must stay interactive
    // meanwhile.
    load(id, readings) {
      session = id;
      if (readings > AUTO_RENDER_READINGS) {
        clear(images);
        info.textContent = `${readings} sample readings: press Render for the colour and lit spheres (on a session this large the daemon needs several seconds the first time, more when busy; the answer is then kept).`;
        return Promise.resolve();
      }
      return render();
    },
  };
}
