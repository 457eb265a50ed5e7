// The Python names the page needs (state classes, autonomy levels, result codes, the machine's
// outcomes, specification sections), as GET /api/vocabulary serves them: loaded once at start,
// before anything is shown, so the page keeps no copies of its own.
import { api } from './api.js';

let names = null;

export async function loadVocabulary() {
  names = await api('GET', '/api/vocabulary');
}

export function vocabulary() {
  return names;
}
