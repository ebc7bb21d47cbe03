// A throwaway PostgreSQL server for the web tests (Debian's postgresql-15 binaries, as the C++
// archive tests' tests/support/pg/server.h): its own data directory under /tmp, a unix socket
// there and a free TCP port on 127.0.0.1, trust authentication for the one role `brdf`. As root
// it runs as `nobody` (PostgreSQL refuses root). BRDF_PG_BIN overrides where the binaries are.
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, readdirSync, existsSync, readFileSync, chownSync, chmodSync, openSync, rmSync } from 'node:fs';
import { createServer } from 'node:net';
import { join } from 'node:path';

function binDir() {
  if (process.env.BRDF_PG_BIN) return process.env.BRDF_PG_BIN;
  const root = '/usr/lib/postgresql';
  const found = existsSync(root) ? readdirSync(root).map((v) => join(root, v, 'bin')).filter((b) => existsSync(join(b, 'initdb'))).sort() : [];
  if (!found.length) throw new Error('PostgreSQL server binaries not found (/usr/lib/postgresql/<version>/bin/initdb); run deploy/install-deps.sh (package postgresql-15)');
  return found.at(-1);
}

export function freePort() {
  return new Promise((resolve, reject) => {
    const s = createServer();
    s.on('error', reject);
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
  });
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

export async function startPostgres() {
  const bin = binDir();
  const dir = mkdtempSync('/tmp/brdf-web-pg-');
  const root = process.getuid() === 0;
  // nobody:nogroup on Debian.
  const uid = 65534;
  const gid = 65534;
  if (root) chownSync(dir, uid, gid);
  chmodSync(dir, 0o700);
  const as = (args) => (root ? ['setpriv', ['--reuid=nobody', '--regid=nogroup', '--clear-groups', '--', ...args]] : [args[0], args.slice(1)]);
  const [initCmd, initArgs] = as([join(bin, 'initdb'), '-D', join(dir, 'data'), '-U', 'brdf', '--auth=trust', '-E', 'UTF8', '--locale=C', '--no-sync']);
  try { execFileSync(initCmd, initArgs, { stdio: ['ignore', 'pipe', 'pipe'] }); } catch (e) { throw new Error(`initdb failed: ${e.stderr || e.message}`); }
  const port = await freePort();
  const log = join(dir, 'postgres.log');
  if (root) chownSync(dir, uid, gid);
  const [cmd, args] = as([join(bin, 'postgres'), '-D', join(dir, 'data'), '-k', dir, '-p', String(port), '-c', 'listen_addresses=127.0.0.1',
    '-c', 'fsync=off', '-c', 'full_page_writes=off', '-c', 'shared_buffers=32MB', '-c', 'logging_collector=off']);
  const proc = spawn(cmd, args, { stdio: ['ignore', 'ignore', openSync(log, 'w')] });
  const deadline = Date.now() + 30000;
  for (;;) {
    if (proc.exitCode !== null) throw new Error(`postgres exited while starting: ${readFileSync(log, 'utf8').slice(-2000)}`);
    // postmaster.pid's 8th line is "ready" once the server accepts connections.
    const pid = join(dir, 'data', 'postmaster.pid');
    if (existsSync(pid) && (readFileSync(pid, 'utf8').split('\n')[7] || '').includes('ready')) break;
    if (Date.now() > deadline) throw new Error(`postgres did not become ready within 30 s: ${readFileSync(log, 'utf8').slice(-2000)}`);
    await sleep(50);
  }
  return {
    conninfo: `host=${dir} port=${port} dbname=postgres user=brdf`,
    log,
    async stop() {
      if (proc.exitCode === null) {
        proc.kill('SIGINT'); // fast shutdown
        await new Promise((r) => { const t = setTimeout(() => { proc.kill('SIGKILL'); r(); }, 10000); proc.on('exit', () => { clearTimeout(t); r(); }); });
      }
      rmSync(dir, { recursive: true, force: true });
    },
  };
}
