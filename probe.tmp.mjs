import { chromium } from 'playwright-core';
import { writeFileSync } from 'node:fs';
const [file, x, y, w, h] = process.argv.slice(2);
const b = await chromium.launch({ executablePath: '/usr/lib/chromium/chromium', args: ['--no-sandbox'] });
const p = await b.newPage({ viewport: { width: Number(w), height: Number(h) } });
writeFileSync('/tmp/crop.html', `<body style="margin:0"><div style="width:${w}px;height:${h}px;overflow:hidden"><img src="file://${file}" style="margin-left:-${x}px;margin-top:-${y}px"></div></body>`);
await p.goto('file:///tmp/crop.html');
await p.screenshot({ path: '/tmp/crop.png' });
await b.close();
