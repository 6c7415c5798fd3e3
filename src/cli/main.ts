#!/usr/bin/env node
/**
 * The `satscope` executable: runs the command (command.ts) in a Node started with the options
 * relaunch.ts gives, and ends as it does. Started without them (`npx satscope`, `node main.js`),
 * it starts one that has them, without loading the library here.
 */
import { fileURLToPath } from 'node:url';
import { mustRelaunch, relaunch } from './relaunch.js';

const args = process.argv.slice(2);
process.exitCode = mustRelaunch() ? await relaunch(fileURLToPath(import.meta.url), args) : await (await import('./command.js')).run(args);
