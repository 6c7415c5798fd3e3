export * from './browser.js';
export * from './load.js';
export * from './policy.js';
export * from './pty-serial.js';
