// Bundles the console and explorer into one directory (dist/, or --outDir from the CMake build)
// that brdfd serves; every asset is local (no CDN), script only as files (the gateway's CSP
// allows no inline script).
import { defineConfig } from 'vite';

export default defineConfig({
  base: './',
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    minify: false, // plotly comes minified; ours is small and stays readable
    chunkSizeWarningLimit: 6000,
    modulePreload: { polyfill: false },
  },
});
