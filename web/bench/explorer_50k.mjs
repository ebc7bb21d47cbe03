// The explorer on a 50,000-reading session, in headless Chromium: how long the first view takes
// (sign-in done; from opening #explorer to Figure 7's two 3D point clouds drawn and the polar
// plot of the plane of incidence drawn) and how long a new direction's spectrum takes (from the
// click to the interpolated spectrum and its vertex spectra drawn), as medians, each with a
// baseline measured in the same run, interleaved: the first view of the SAME explorer on a small
// session (500 readings, its own brdfd) and the gateway's no-op round trip (an Interpolate
// without a direction: authorized, parsed and refused before any index lookup). Also printed:
// the gateway call behind Figure 7 alone (Data.StreamReadingPoints from the page: time, bytes).
// The sessions are bench_storage's (completed isotropic sessions of N sample readings at the
// rig's poses, the paper's grid repeated and jittered); brdfd runs without a rig.
//   BRDF_BUILD_DIR=build node web/bench/explorer_50k.mjs [readings]    (from web/: node bench/…)
//   BRDF_BENCH_DB=<50k db> BRDF_BENCH_SMALL_DB=<500 db>: reuse sessions made before (creating the
//   big one takes minutes; the bench prints where it kept them). BRDF_BENCH_VIEWS: first views
//   per session (default 5). BRDF_BENCH_WEB_ROOT: serve another build of the front end (e.g.
//   main's, built with vite --outDir) to compare two builds on the same sessions.
//
// Measured (2026-12-04, this machine, load average 5–7 from two other builds; chromium with
// SwiftShader, no GPU):
//   before (Figure 7 from StreamReadings?omit=radiance, one JSON event per reading, 29 MB;
//   plotly scatter3d, a glyph mesh per marker): first view 26.7 s (text only; the WebGL frames
//   took another 15 s), new direction 98.9 ms, no-op 18.8 ms.
//   after (5 views; Figure 7 from Data.StreamReadingPoints, 3.81 MB in 8 events; three.js
//   points; plotly loaded after Figure 7 is drawn): first view, Figure 7 drawn, median 1456 ms
//   (500-reading session 769 ms, ratio 1.89); with the polar plot 3758 ms (small 2910 ms, ratio
//   1.29: plotly's load and parse, ~2 s under that load, is most of it); new direction median
//   90.0 ms, no-op 8.6 ms, ratio 10.5; StreamReadingPoints alone 872 ms.
//   2026-12-05 (plotly partial bundle, polar batch beside the readings' stream, vertex spectra
//   in the interpolation's answer; the sessions now at the rig's poses, 6.01 MB of points):
//   with the polar plot median 1646 ms (small 718 ms, ratio 2.29; main's build on the same
//   sessions just before: 4689 ms), new direction 98.1 ms (main's 104.1 ms); bench/README.md.
//   2026-12-05, later (the lit sphere rendered at load then): views after the first took 20–60 s,
//   each reload asking the daemon for the same ~50 s render again. With RenderAppearance's answer
//   cache and no render at load above 20,000 readings: 5 views, Figure 7 median 1693 ms (small
//   1096 ms, ratio 1.54), with the polar plot 2009 ms (small 1374 ms, ratio 1.46); new direction
//   112.2 ms, no-op 11.6 ms. A second run (3 views, load 2–3): Figure 7 2475 ms, with the polar
//   plot 2925 ms (ratios 2.04, 2.25); new direction 74.0 ms, of which the Interpolate call 16.0 ms.
//   2026-12-05, stop 34 (ReadingPoints read without spectra and rounded to 1e-6°, 3.52 MB; the
//   page's sign-in and the readings asked for sooner): three runs, Figure 7 median 1031, 1290,
//   1087 ms (ratios to the small session 1.30, 1.37, 1.26; before, in the same hour, 1718 ms and
//   1.92), with the polar plot 1288, 1621, 1358 ms (before 2044 ms); new direction 58.4, 73.2,
//   81.7 ms (before 55.3 ms). bench/README.md has the table.
//   2026-12-06 (issue 41: the fill chain's model fitted in one pass over the bands and beside the
//   Delaunay build), the lit spheres' first render, BRDF_BENCH_VIEWS=1, 3 repetitions, main's
//   brdfd interleaved, load 11–17: 101 bands median 18.33 s (main 31.23 s), 401 bands 28.38 s
//   (main 74.17 s, once); again 0.05 s for both. With the fit's sums eight bands at a time
//   (85e5df8; load 7–13): 101 bands 8.98 s (main 11.36 s), 401 bands 9.30 s. bench/README.md,
//   "The explorer's first lit spheres", has brdfd's CPU time beside it.
//   2026-12-07 (issue 41: the fallback answers the colour's 45°:0° from the readings near it,
//   proved equal to the whole Delaunay triangulation's, instead of triangulating 200,000 points),
//   BRDF_BENCH_VIEWS=1, 3 repetitions, main's brdfd interleaved, load 14–21: 101 bands median
//   5.38 s (main 21.61 s), 401 bands 18.09 s (main 27.01 s; the model fit is what is left);
//   again 0.05 s. brdfd CPU per first render 1.52 s (main 5.08 s) and 4.52 s (main 8.85 s).
//   2026-12-07, later (issue 41: the model fit's lobe once per reading, its three searches side by
//   side and several evaluations per pass over 16-band panels; the same bits), against the change
//   above, interleaved, 3 repetitions, load 2.9–8.3: 401 bands 2.13 s (4.45 s), 101 bands
//   1.40 s (1.83 s); brdfd CPU at load ~3.6: 2.49 s (3.90 s) and 1.20 s (1.48 s). bench/README.md.
import puppeteer from 'puppeteer-core';
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, writeFileSync, openSync, readFileSync, copyFileSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { createInterface } from 'node:readline';

const build = process.env.BRDF_BUILD_DIR;
const readings = Number(process.argv[2] || 50000);
const smallReadings = 500;
const dir = mkdtempSync(join(tmpdir(), 'brdf-web-bench-'));
const token = 'bench-analyst-token-0123456789';

// A session database in `dir` (copied from `keep` when given, else created there).
function sessionDb(name, n, keep) {
  const db = join(dir, `${name}.db`);
  const t0 = Date.now();
  if (keep && existsSync(keep)) {
    copyFileSync(keep, db);
  } else {
    execFileSync(join(build, 'bench/daemon/bench_storage'), ['create', '--db', db, '--readings', String(n)]);
    const kept = join(tmpdir(), `brdf-web-bench-${n}.db`);
    copyFileSync(db, kept);
    console.log(`session of ${n} readings created in ${Date.now() - t0} ms (kept as ${kept}; pass it as ${name === 'big' ? 'BRDF_BENCH_DB' : 'BRDF_BENCH_SMALL_DB'})`);
  }
  return db;
}

// brdfd on `db` without a rig; resolves with the web console's URL.
async function startDaemon(name, db) {
  const sub = join(dir, name);
  execFileSync('mkdir', ['-p', sub]);
  writeFileSync(join(sub, 'brdfd.toml'), `[server]
listen = "127.0.0.1:0"
[storage]
database = "${db}"
[meter]
port = "${sub}/no-meter"
[stage]
address = "127.0.0.1:1"
[[auth.tokens]]
name = "bench"
token = "${token}"
role = "analyst"
[web]
listen = "127.0.0.1:0"
${process.env.BRDF_BENCH_WEB_ROOT ? `root = "${process.env.BRDF_BENCH_WEB_ROOT}"` : ''}
[log]
level = "warn"
`);
  const daemon = spawn(join(build, 'daemon/brdfd'), ['--config', join(sub, 'brdfd.toml')], { stdio: ['ignore', 'pipe', openSync(join(sub, 'brdfd.log'), 'w')] });
  const url = await new Promise((resolve, reject) => {
    daemon.on('exit', (c) => reject(new Error(`brdfd exited ${c}: ${readFileSync(join(sub, 'brdfd.log'), 'utf8')}`)));
    createInterface({ input: daemon.stdout }).on('line', (l) => { const m = /^brdfd web console on (\S+)/.exec(l); if (m) resolve(m[1]); });
  });
  return { daemon, url };
}

const big = await startDaemon('big', sessionDb('big', readings, process.env.BRDF_BENCH_DB));
const small = await startDaemon('small', sessionDb('small', smallReadings, process.env.BRDF_BENCH_SMALL_DB));
const median = (a) => { const s = [...a].sort((x, y) => x - y); return s[Math.floor(s.length / 2)]; };
const browser = await puppeteer.launch({ executablePath: process.env.BRDF_CHROMIUM || '/usr/bin/chromium', headless: true, args: ['--no-sandbox', '--disable-dev-shm-usage', '--enable-unsafe-swiftshader', '--use-angle=swiftshader'], defaultViewport: { width: 1400, height: 1000 }, protocolTimeout: 900000 });

async function signedIn(url) {
  const page = await browser.newPage();
  await page.goto(url);
  await page.waitForSelector('#login-view:not([hidden])'); // shown once the page knows its server
  await page.type('#token', token);
  await page.click('#login-button');
  await page.waitForFunction(() => document.getElementById('who').textContent === 'analyst');
  return page;
}

// From opening #explorer to Figure 7's two point clouds drawn (`fig7`, one frame after), and on
// to the plane of incidence's polar plot drawn as well (`full`: plotly is loaded for it).
async function firstView(page, url) {
  await page.bringToFront(); // a tab in the background gets no animation frames
  await page.goto('about:blank'); // a real page load each time (sessionStorage stays)
  const s = Date.now();
  await page.goto(`${url}#explorer`);
  await page.waitForFunction(() => /sample readings loaded/.test(document.getElementById('explorer-info')?.textContent || ''), { timeout: 120000, polling: 10 });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
  const fig7 = Date.now() - s;
  await page.waitForFunction(() => document.querySelector('#polar .trace'), { timeout: 120000, polling: 10 });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => r())));
  return { fig7, full: Date.now() - s };
}

try {
  const page = await signedIn(big.url);
  const smallPage = await signedIn(small.url);
  const views = [];
  const smallViews = [];
  for (let i = 0; i < Number(process.env.BRDF_BENCH_VIEWS || 5); i++) {
    views.push(await firstView(page, big.url));
    smallViews.push(await firstView(smallPage, small.url));
    console.log(`first view: Figure 7 ${views.at(-1).fig7} ms, with the polar plot ${views.at(-1).full} ms (${await page.$eval('#explorer-info', (e) => e.textContent)}); small session ${smallViews.at(-1).fig7} / ${smallViews.at(-1).full} ms`);
  }
  await page.bringToFront();
  const points = await page.evaluate(async () => {
    const s = performance.now();
    const r = await fetch('/api/brdf.v1.Data/StreamReadingPoints', { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${sessionStorage.getItem('brdfd.token')}` }, body: JSON.stringify({ session_id: '1', kinds: ['READING_KIND_SAMPLE'] }) });
    const text = await r.text();
    return { ms: performance.now() - s, bytes: text.length, events: text.split('\n\n').length - 1 };
  });
  console.log(`Figure 7's gateway call alone (Data.StreamReadingPoints, ${readings} readings): ${points.ms.toFixed(0)} ms, ${(points.bytes / 1e6).toFixed(2)} MB in ${points.events} events`);
  await page.screenshot({ path: join(dir, 'explorer-50k.png'), fullPage: true });
  const spectra = [];
  const noop = [];
  const calls = []; // the Interpolate call alone, as the page reports it ("in N ms")
  for (let i = 0; i < 15; i++) {
    const dirn = { ti: 10 + (i * 7) % 60, to: 15 + (i * 11) % 60, phi: 20 + (i * 13) % 140 };
    const ms = await page.evaluate(async (d) => {
      document.getElementById('q-theta-i').value = d.ti;
      document.getElementById('q-theta-o').value = d.to;
      document.getElementById('q-phi').value = d.phi;
      document.getElementById('interp-status')?.remove();
      const s = performance.now();
      document.getElementById('interpolate').click();
      for (;;) {
        await new Promise((r) => requestAnimationFrame(r));
        const st = document.getElementById('interp-status');
        const traces = document.querySelectorAll('#interp-spectrum .scatterlayer .trace').length;
        if (st && (traces >= 2 || /status|empty|outside|no_/.test(st.textContent) || st.classList.contains('error'))) {
          return { ms: performance.now() - s, call: Number((/ in (\d+) ms/.exec(st.textContent) || [])[1]) };
        }
      }
    }, dirn);
    spectra.push(ms.ms);
    calls.push(ms.call);
    noop.push(await page.evaluate(async () => {
      const s = performance.now();
      await fetch('/api/brdf.v1.Interpolation/Interpolate', { method: 'POST', headers: { 'Content-Type': 'application/json', Authorization: `Bearer ${sessionStorage.getItem('brdfd.token')}` }, body: JSON.stringify({ session_id: '1' }) });
      return performance.now() - s;
    }));
  }
  console.log(`a new direction's spectrum (click → interpolated and vertex spectra drawn): median ${median(spectra).toFixed(1)} ms, max ${Math.max(...spectra).toFixed(1)} ms over ${spectra.length}; the Interpolate call alone (page's fetch, vertex spectra included) median ${median(calls).toFixed(1)} ms`);
  console.log(`gateway no-op round trip: median ${median(noop).toFixed(1)} ms; ratio spectrum/no-op ${(median(spectra) / median(noop)).toFixed(1)}`);
  for (const [key, what] of [['fig7', "Figure 7's point clouds drawn"], ['full', 'and the polar plot drawn']]) {
    const b = median(views.map((v) => v[key]));
    const sm = median(smallViews.map((v) => v[key]));
    console.log(`first view (${what}): median ${b} ms over ${views.length} (target < 2000 ms); small session (${smallReadings} readings) ${sm} ms; ratio 50k/small ${(b / sm).toFixed(2)}`);
  }
  console.log(`new direction: median ${median(spectra).toFixed(1)} ms (target < 100 ms)`);
  // The lit spheres, which a session this large renders only when asked (Render): the first time
  // (indexes built), then again (the daemon's kept answer). BRDF_BENCH_RENDER=0 skips it.
  if (process.env.BRDF_BENCH_RENDER !== '0') {
    for (const pass of ['first', 'again']) {
      const ms = await page.evaluate(async () => {
        document.getElementById('appearance-images').replaceChildren();
        const s = performance.now();
        document.getElementById('appearance-render').click();
        for (;;) {
          await new Promise((r) => setTimeout(r, 50));
          if (document.getElementById('appearance-sphere-A')) return performance.now() - s;
          const info = document.getElementById('appearance-info').textContent;
          if (!/rendering/.test(info)) throw new Error(`the render failed: ${info}`);
        }
      });
      console.log(`lit spheres (Render), ${pass}: ${(ms / 1000).toFixed(2)} s`);
    }
  }
  console.log(`screenshot: ${join(dir, 'explorer-50k.png')}`);
} finally {
  await browser.close();
  big.daemon.kill('SIGTERM');
  small.daemon.kill('SIGTERM');
}
