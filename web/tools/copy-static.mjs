// Copies the page's static files next to the bundle esbuild wrote.
import { copyFileSync, mkdirSync } from 'node:fs';
mkdirSync('dist', { recursive: true });
for (const f of ['index.html', 'tiles.html', 'style.css']) copyFileSync(`src/${f}`, `dist/${f}`);
