#!/usr/bin/env node
/** The `satscope` executable: runs the command (command.ts) and ends with its exit code. */
import { run } from './command.js';

process.exitCode = await run(process.argv.slice(2));
