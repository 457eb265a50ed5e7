// The page's client of the server's JSON API and of its server-sent event streams.

export async function api(method, path, body) {
  const options = { method, headers: {} };
  // The server takes POSTs only as JSON (what no cross-site form can send): a POST without
  // a body sends {}.
  if (body === undefined && method === 'POST') body = {};
  if (body !== undefined) {
    options.headers['Content-Type'] = 'application/json';
    options.body = JSON.stringify(body);
  }
  const response = await fetch(path, options);
  const data = await response.json().catch(() => ({}));
  if (!response.ok) throw answerError(response, data);
  return data;
}

// The Error of a 4xx/5xx answer: its message, `error` kind as `code`, item, status, Retry-After.
function answerError(response, data) {
  const error = new Error(data.message || `${response.status} ${response.statusText}`);
  error.code = data.error || String(response.status);
  error.item = data.item;
  error.status = response.status;
  error.retryAfter = response.headers ? Number(response.headers.get('Retry-After')) || 0 : 0;
  return error;
}

// POST ``body`` and read the answer as JSON lines (application/x-ndjson), calling ``onLine``
// with each as it arrives; a refusal before the stream throws as api() does.
export async function postForLines(path, body, onLine) {
  const response = await fetch(path, { method: 'POST', body: JSON.stringify(body),
    headers: { 'Content-Type': 'application/json', Accept: 'application/x-ndjson' } });
  if (!response.ok) throw answerError(response, await response.json().catch(() => ({})));
  const reader = response.body.getReader();
  const decoder = new TextDecoder();
  let pending = '';
  for (;;) {
    const { value, done } = await reader.read();
    pending += decoder.decode(value || new Uint8Array(), { stream: !done });
    const lines = pending.split('\n');
    pending = lines.pop();
    for (const line of lines) if (line.trim()) onLine(JSON.parse(line));
    if (done) break;
  }
  if (pending.trim()) onLine(JSON.parse(pending));
}

// A stream's ``{"error": {...}}`` line as the Error api() would have thrown.
export function lineError(body) {
  return answerError({ status: 0, statusText: '', headers: null }, body);
}

// The one reader of the server-sent events of jobs and simulations: `progress` with each
// snapshot, `finished` with the last one, `broken` when the stream fails. Returns the EventSource.
export function streamEvents(url, handlers) {
  const source = new EventSource(url);
  source.addEventListener('progress', (message) => handlers.progress(JSON.parse(message.data)));
  source.addEventListener('finished', (message) => {
    source.close();
    handlers.finished(JSON.parse(message.data));
  });
  source.onerror = () => {
    source.close();
    handlers.broken();
  };
  return source;
}
