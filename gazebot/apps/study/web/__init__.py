"""The study in the browser: a Flask app (:func:`create_app`) over a rendered study folder and its
SQLite answers, served by waitress (:func:`serve`)."""

from gazebot.apps.study.web.app import create_app
from gazebot.apps.study.web.server import serve

__all__ = ["create_app", "serve"]
