"""``ros2nb-hub-hand-in``: the hub's hand-in service, which keeps each hand-in and its time.

Runs on the classroom server as a JupyterHub managed service (``environment/
jupyterhub_config.py`` starts it, as root, with the hub; its address is
``/services/hand-in/``).  A learner is who the hub says the request's token or cookie belongs
to (JupyterHub's ``HubOAuthenticated``), never a name in the request, so a learner can hand
in, and read, only their own.  What it answers is typed once, in :mod:`ros2nb.hand_ins`:

- ``POST api/hand-ins/<NN-title>`` (the notebook's bytes; ``ros2nb.hand_in("03")``): the
  notebook is stored with the time by this service's clock (:mod:`.hand_in_store`), and
  the answer says it, with the learner's due date (their extension's, if any) and how late;
- ``GET api/hand-ins``: each of the learner's notebooks: when handed in, when due, whether
  feedback was released (``ros2nb.progress()`` shows them);
- ``GET feedback/`` and ``GET feedback/<NN-title>.html``: the learner's own feedback pages,
  as the instructor released them (``make hub-feedback``), under the pages' own strict
  Content-Security-Policy (nothing on them runs or loads).

What it says of a notebook (due dates from ``course.toml`` and ``extensions.toml``, read at
each request) is :mod:`.schedule`'s.
"""

from __future__ import annotations

import argparse
import dataclasses
import html
import json
import logging
import os
from pathlib import Path
from typing import Any, Optional
from urllib.parse import urlparse

from jupyterhub.services.auth import HubOAuthCallbackHandler, HubOAuthenticated
from ros2nb.hand_ins import SAVED_HEADER, Standing
from tornado import ioloop, web

from ..grading.reports.feedback import CSP
from ..grading.intake.hand_in_times import TimeProblem, parse_time
from ..paths import EXTENSIONS, SETTINGS
from .hand_in_store import MAX_NOTEBOOK_BYTES, Refused, Store
from .schedule import LOG, Schedule, status

log = logging.getLogger(LOG)


class Learners(HubOAuthenticated, web.RequestHandler):
    """A request of one learner, who the hub says it is from.

    Its handlers end with ``finish`` and never await the Future it returns: that only says
    when tornado has written the response out, which it does without them.
    """

    def initialize(self, store: Store, schedule: Schedule) -> None:
        self.store, self.schedule = store, schedule

    def learner(self) -> str:
        """The learner's hub name.

        :raises web.HTTPError: 403 when the request is not a hub user's.
        """
        model = self.get_current_user()
        if not model or model.get('kind', 'user') != 'user':
            raise web.HTTPError(403, 'log in to the hub as a learner')
        try:
            self.store.folder(str(model['name']))
        except Refused as why:
            raise web.HTTPError(403, f'{why}: ask your instructor') from None
        return str(model['name'])

    def reply(self, value: Any) -> None:
        self.set_header('Content-Type', 'application/json')
        _ = self.finish(json.dumps(dataclasses.asdict(value)))

    def write_error(self, status_code: int, **kwargs: Any) -> None:
        """One line of text, no page and no traceback."""
        self.set_header('Content-Type', 'text/plain; charset=utf-8')
        error = kwargs.get('exc_info', (None, None))[1]
        _ = self.finish(getattr(error, 'log_message', None) or self._reason)


class HandIns(Learners):
    """``api/hand-ins``: the learner's notebooks; ``api/hand-ins/<NN-title>``: hand one in."""

    def get(self) -> None:
        learner = self.learner()
        try:
            notebooks = tuple(status(self.store, self.schedule, learner, n)
                              for n in self.store.notebooks)
        except TimeProblem as why:  # the store's record, not the learner's doing
            raise web.HTTPError(500, f'{why}: ask your instructor to look at the hand-in '
                                     'store') from None
        self.reply(Standing(learner, notebooks,
                            f'{os.environ.get("JUPYTERHUB_SERVICE_PREFIX", "/")}feedback/'))

    def post(self, notebook: str) -> None:
        learner = self.learner()
        saved = self.request.headers.get(SAVED_HEADER)
        try:
            when = parse_time(saved, SAVED_HEADER) if saved else None
            stored = self.store.hand_in(learner, notebook, self.request.body, when)
        except (Refused, TimeProblem) as why:
            raise web.HTTPError(400, str(why)) from None
        log.info('%s handed in %s at %s', learner, notebook, stored.at.isoformat())
        self.reply(status(self.store, self.schedule, learner, notebook, stored.saved))


class Feedback(Learners):
    """``feedback/``: the learner's released pages; ``feedback/<NN-title>.html``: one."""

    def get(self, notebook: Optional[str] = None) -> None:
        if not self.current_user:
            self.redirect(self.get_login_url())  # a browser: through the hub's login
            return
        learner = self.learner()
        self.set_header('Content-Security-Policy', CSP)
        self.set_header('Content-Type', 'text/html; charset=utf-8')
        if notebook is None:
            items = ''.join(f'<li><a href="{n}.html">{n}</a></li>'
                            for n in self.store.feedback(learner))
            _ = self.finish(
                f'<!doctype html><html><head><meta charset="utf-8"><title>Your feedback'
                f'</title></head><body><h1>Your feedback, {html.escape(learner)}</h1><ul>'
                f'{items or "<li>none released yet</li>"}</ul></body></html>')
            return
        page = self.store.page(learner, notebook)
        if page is None:
            raise web.HTTPError(404, f'no feedback on {notebook} released to you yet')
        _ = self.finish(page)


def application(store: Store, schedule: Schedule, prefix: str) -> web.Application:
    """The service's tornado application under ``prefix`` (``/services/hand-in/``); its own
    address leads to the learner's feedback."""
    given = {'store': store, 'schedule': schedule}
    return web.Application([
        (prefix, web.RedirectHandler, {'url': f'{prefix}feedback/'}),
        (f'{prefix}api/hand-ins', HandIns, given),
        (f'{prefix}api/hand-ins/([0-9][0-9]-[a-z0-9-]+)', HandIns, given),
        (f'{prefix}feedback/?', Feedback, given),
        (f'{prefix}feedback/([0-9][0-9]-[a-z0-9-]+)\\.html', Feedback, given),
        (f'{prefix}oauth_callback', HubOAuthCallbackHandler),
    ], cookie_secret=os.urandom(32), max_body_size=MAX_NOTEBOOK_BYTES + 1)


def main(argv: Optional[list[str]] = None) -> None:
    """Serve the hand-in service where JupyterHub says (``JUPYTERHUB_SERVICE_URL``)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--store', type=Path, required=True, help='the hand-in store (root\'s)')
    parser.add_argument('--settings', type=Path, default=SETTINGS)
    parser.add_argument('--extensions', type=Path)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format='[hand-in %(asctime)s] %(message)s')
    schedule = Schedule(args.settings, args.extensions or args.settings.parent / EXTENSIONS)
    url = urlparse(os.environ['JUPYTERHUB_SERVICE_URL'])
    prefix = os.environ.get('JUPYTERHUB_SERVICE_PREFIX', '/services/hand-in/')
    application(Store(args.store), schedule, prefix).listen(url.port or 80, url.hostname or '')
    log.info('serving %s at %s, store %s', prefix, url.geturl(), args.store)
    ioloop.IOLoop.current().start()


if __name__ == '__main__':
    main()
