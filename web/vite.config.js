// Bundles the console and explorer into one directory (dist/, or --outDir from the CMake build)
// that brdfd serves; every asset is local (no CDN), script only as files (the gateway's CSP
// allows no inline script).
import { defineConfig } from 'vite';

export default defineConfig({
  base: './',
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    // Minified: re-emitted unminified, plotly's 5.2 MB grew to 7.6 MB (and three.js to 1.2 MB)
    // for the browser to parse on every first view.
    minify: 'esbuild',
    chunkSizeWarningLimit: 6000,
    modulePreload: { polyfill: false },
  },
});
