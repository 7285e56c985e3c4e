import { defineConfig } from 'vite';

// The built editor goes to dist/; the C++ build copies it beside the lidarshop executable (build/release/web).
export default defineConfig({
  base: './',
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 1000 },
  test: { include: ['tests/**/*.test.ts'], environment: 'node' },
});
