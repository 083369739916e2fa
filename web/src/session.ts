// The login (POST /api/login sets an HttpOnly cookie the page never sees) and who is here.
import { h, clear } from "./dom";
import type { Session } from "./types";

export async function currentSession(): Promise<Session | null> {
  const r = await fetch("/api/session", { credentials: "same-origin" });
  if (r.status === 401) return null;
  if (!r.ok) throw new Error(`session: HTTP ${r.status}`);
  return (await r.json()) as Session;
}

export async function logout(): Promise<void> {
  await fetch("/api/logout", { method: "POST", credentials: "same-origin" });
}

// The login form; resolves once a login succeeded.
export function showLogin(view: HTMLElement): Promise<void> {
  return new Promise((resolve) => {
    const user = h("input", { name: "user", autocomplete: "username", required: true });
    const password = h("input", { name: "password", type: "password", autocomplete: "current-password", required: true });
    const message = h("p", { class: "form-error", role: "alert" });
    const form = h(
      "form",
      { class: "login", id: "login" },
      h("h1", {}, "Log in to the cell"),
      h("label", {}, "User ", user),
      h("label", {}, "Password ", password),
      h("button", { type: "submit", class: "big" }, "Log in"),
      message,
    );
    form.addEventListener("submit", async (e) => {
      e.preventDefault();
      message.textContent = "";
      const r = await fetch("/api/login", {
        method: "POST",
        credentials: "same-origin",
        headers: { "Content-Type": "application/json" },
        body: JSON.stringify({ user: user.value, password: password.value }),
      });
      password.value = "";
      if (r.ok) return resolve();
      const body = await r.json().catch(() => ({ error: `HTTP ${r.status}` }));
      message.textContent = body.error ?? `HTTP ${r.status}`;
    });
    clear(view, form);
    user.focus();
  });
}
