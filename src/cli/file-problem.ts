/** Why a file could not be read or written, in the words the commands print. */

/**
 * `error` from the file system said plainly: `missing` for ENOENT (what is missing depends on
 * whether a file was read or written), the others the same for every command.
 */
export function fileProblem(error: unknown, missing: string): string {
  const code = (error as NodeJS.ErrnoException).code;
  return code === 'ENOENT' ? missing : code === 'EISDIR' ? 'it is a directory' : code === 'EACCES' ? 'permission denied' : String(error);
}
