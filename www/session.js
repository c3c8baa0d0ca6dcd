// What the page remembers: the program, the options and the methods, kept in local storage on
// every change and carried whole in a shareable link (`#s=` then base64url of the JSON), so a
// reload or a link brings back exactly the same shape and settings.

const KEY = 'isoforge.session.v1';

/** base64url of the UTF-8 bytes of `text` (programs may hold any character). */
function encode(text) {
  const bytes = new TextEncoder().encode(text);
  let binary = '';
  for (const b of bytes) binary += String.fromCharCode(b);
  return btoa(binary).replaceAll('+', '-').replaceAll('/', '_').replace(/=+$/, '');
}

function decode(code) {
  const binary = atob(code.replaceAll('-', '+').replaceAll('_', '/'));
  return new TextDecoder().decode(Uint8Array.from(binary, (c) => c.charCodeAt(0)));
}

/** The link to this page holding `session`. */
export function shareUrl(session, location = window.location) {
  return `${location.origin}${location.pathname}#s=${encode(JSON.stringify(session))}`;
}

/** The session in `hash` (`#s=…`), or null when there is none or it does not decode. */
export function fromHash(hash) {
  const m = /^#s=([A-Za-z0-9_-]+)$/.exec(hash);
  if (!m) return null;
  try {
    const session = JSON.parse(decode(m[1]));
    return typeof session === 'object' && session !== null && typeof session.program === 'string' ? session : null;
  } catch {
    return null;
  }
}

/** The session saved by the last visit, or null. */
export function restore(storage = window.localStorage) {
  try {
    const session = JSON.parse(storage.getItem(KEY) ?? 'null');
    return session && typeof session.program === 'string' ? session : null;
  } catch {
    return null;
  }
}

export function save(session, storage = window.localStorage) {
  try {
    storage.setItem(KEY, JSON.stringify(session));
  } catch {
    // Storage full or disabled (private mode): the page still works, it just forgets.
  }
}
