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
  if (!response.ok) {
    const error = new Error(data.message || `${response.status} ${response.statusText}`);
    error.code = data.error || String(response.status);
    error.item = data.item;
    error.status = response.status;
    error.retryAfter = Number(response.headers.get('Retry-After')) || 0;
    throw error;
  }
  return data;
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
