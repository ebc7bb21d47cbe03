// brdfd's JSON gateway: POST /api/brdf.v1.<Service>/<Method> with the request as protobuf JSON
// and the tab's bearer token; streams come back as server-sent events (read with fetch, since
// EventSource cannot send a token).
const KEY = 'brdfd.token';

export function getToken() { return sessionStorage.getItem(KEY) || ''; }
export function setToken(t) { if (t) sessionStorage.setItem(KEY, t); else sessionStorage.removeItem(KEY); }

export class ApiError extends Error {
  constructor(code, message, status) { super(`${code}: ${message}`); this.code = code; this.status = status; this.detail = message; }
}

function headers() {
  const h = { 'Content-Type': 'application/json' };
  const t = getToken();
  if (t) h.Authorization = `Bearer ${t}`;
  return h;
}

async function errorOf(r) {
  const text = await r.text();
  try { const e = JSON.parse(text); return new ApiError(e.code, e.message, r.status); }
  catch { return new ApiError(`HTTP_${r.status}`, text.trim(), r.status); }
}

// `timeoutS`: the call's deadline in seconds when the gateway's default (60 s) is too short.
export async function call(method, body = {}, timeoutS = 0) {
  const query = timeoutS ? `?timeout_s=${timeoutS}` : '';
  const r = await fetch(`/api/brdf.v1.${method}${query}`, { method: 'POST', headers: headers(), body: JSON.stringify(body) });
  if (!r.ok) throw await errorOf(r);
  return r.json();
}

// Calls a server-streaming method; onMessage(msg) for each message; resolves when the stream
// ends OK, rejects with the reason otherwise. `signal` (AbortController) cancels it. `omit`:
// top-level fields of every answer the gateway leaves out (e.g. ['radiance']).
export async function stream(method, body, onMessage, signal, omit = []) {
  const query = omit.length ? `?omit=${omit.map(encodeURIComponent).join(',')}` : '';
  const r = await fetch(`/api/brdf.v1.${method}${query}`, { method: 'POST', headers: headers(), body: JSON.stringify(body), signal });
  if (!r.ok) throw await errorOf(r);
  const reader = r.body.getReader();
  const decoder = new TextDecoder();
  let buffer = '';
  for (;;) {
    const { value, done } = await reader.read();
    if (done) throw new ApiError('UNAVAILABLE', 'the stream ended without its end event', 0);
    buffer += decoder.decode(value, { stream: true });
    let cut;
    while ((cut = buffer.indexOf('\n\n')) >= 0) {
      const block = buffer.slice(0, cut);
      buffer = buffer.slice(cut + 2);
      let event = 'message';
      let data = '';
      for (const line of block.split('\n')) {
        if (line.startsWith('event: ')) event = line.slice(7);
        else if (line.startsWith('data: ')) data += line.slice(6);
      }
      if (!data) continue;
      const parsed = JSON.parse(data);
      if (event === 'end') {
        if (parsed.code !== 'OK') throw new ApiError(parsed.code, parsed.message, 200);
        return;
      }
      onMessage(parsed);
    }
  }
}

// Who the token is, asked of the server itself (Control.WhoAmI): { name, role, server }, role
// "operator" or "analyst". UNAUTHENTICATED for a token the server does not know.
export function whoAmI() {
  return call('Control/WhoAmI', {});
}
