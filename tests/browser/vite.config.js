// The bundle for the browser test: Neuroglancer's npm package (ES modules meant for a bundler)
// with only the precomputed data source, served as static files from dist/. Vite 7 rather than
// 8: Vite 8 fails to install where a machine's npm is still version 10.
import { existsSync } from "node:fs";
import { createRequire } from "node:module";
import { dirname, join } from "node:path";
import { defineConfig } from "vite";

const require = createRequire(import.meta.url);
const ikonate = dirname(require.resolve("ikonate/package.json"));

// Neuroglancer names a commit of its icon set that is fetched from a Git host, which the CI
// machines do not reach; package.json overrides it with the icon set's registry release, which
// lacks a few icons. Those are drawn blank: the test looks at the 3-D view, not the toolbar.
const blankMissingIcons = {
  name: "blank-missing-icons",
  enforce: "pre",
  resolveId(source) {
    const m = /^ikonate\/icons\/([\w-]+\.svg)\?raw$/.exec(source);
    if (m && !existsSync(join(ikonate, "icons", m[1]))) return "\0blank-icon:" + m[1];
    return null;
  },
  load(id) {
    if (id.startsWith("\0blank-icon:"))
      return 'export default \'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 24 24"></svg>\';';
    return null;
  },
};

// Neuroglancer starts its workers as new Worker(/* webpackChunkName: ... */ new URL(...)), and a
// comment there hides the worker from Vite, which would then inline the worker's entry file
// unbundled (its imports unresolved): the comment is dropped.
const workerChunkNames = {
  name: "drop-worker-chunk-names",
  enforce: "pre",
  transform(code, id) {
    if (!id.includes("/neuroglancer/lib/") || !code.includes("webpackChunkName")) return null;
    return { code: code.replace(/\/\*\s*webpackChunkName:[^*]*\*\/\s*/g, ""), map: null };
  },
};

export default defineConfig({
  base: "",  // relative URLs: the bundle is served from any path
  logLevel: "warn",
  plugins: [blankMissingIcons, workerChunkNames],
  resolve: {
    conditions: [
      "neuroglancer/datasource:none_by_default",
      "neuroglancer/datasource/precomputed:enabled",
    ],
  },
  // Neuroglancer's workers use dynamic imports, and start workers of their own.
  worker: { format: "es", plugins: () => [blankMissingIcons, workerChunkNames] },
  build: {
    outDir: "dist",
    emptyOutDir: true,
    chunkSizeWarningLimit: 8 * 1024 * 1024,
    reportCompressedSize: false,
  },
});
