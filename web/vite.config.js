// Bundles the console and explorer into one directory (dist/, or --outDir from the CMake build)
// that brdfd serves; every asset is local (no CDN), script only as files (the gateway's CSP
// allows no inline script).
import { defineConfig } from 'vite';

// plotly.js's registry imports maplibre-gl's stylesheet for its map traces, which the partial
// bundle (src/plotly_partial.js) does not hold: resolved to nothing rather than shipped (65 kB).
const noMapStylesheet = {
  name: 'no-map-stylesheet',
  enforce: 'pre',
  resolveId: (id) => (id === 'maplibre-gl/dist/maplibre-gl.css' ? '\0no-map-stylesheet' : null),
  load: (id) => (id === '\0no-map-stylesheet' ? '' : null),
};

export default defineConfig({
  base: './',
  plugins: [noMapStylesheet],
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    // Minified: re-emitted unminified, plotly's bundle (then the full 5.2 MB one) grew by half
    // (and three.js to 1.2 MB) for the browser to parse on every first view.
    minify: 'esbuild',
    chunkSizeWarningLimit: 6000,
    modulePreload: { polyfill: false },
  },
});
