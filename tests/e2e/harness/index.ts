export * from './browser.js';
export * from './policy.js';
export * from './pty-serial.js';
